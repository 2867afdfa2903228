/* element_rhs: the rotation step and each element's part of the implicit Euler right-hand
 * side and of the Jacobi diagonal, per sigma point (as kernels/opencl/element_rhs.cl):
 *   frame  = the element's frame at x      (QR or polar, element.h; its first two rows
 *                                           stored, ensemble_layout.h: every CG product of
 *                                           the step uses it)
 *   rhs_e  = f_e(x) - (h + a) K_e v_e
 *   diag_e = diag(R K_e R^T)
 * One invocation per (element, sigma); or, compiled with SF_SIGMA_QUADS (element_rhs_quads),
 * per element and four sigma points (sigma_quads.h). Compiled with SF_FACTOR (*_factor: CG
 * preconditioned by factor_solve), no Jacobi diagonal, as OpenCL's with SF_FACTOR. */
#version 450
#extension GL_GOOGLE_include_directive : require
#include "ensemble_layout.h"

layout(local_size_x = SF_ITEMS_PER_GROUP) in;
/* The rotation method, the scenario's material.rotation (1 polar, 0 QR), set at pipeline
 * creation (specialization constant 0), as OpenCL's build option SF_POLAR_FRAMES: read at run
 * time it was a branch llvmpipe ran both sides of, the polar frame's Newton steps for QR
 * scenarios too (18% of element_rhs on the 4768 liver; bench/RESULTS.md, stop 60). */
layout(constant_id = 0) const uint SF_POLAR_FRAMES = 0u;
#if defined(SF_SIGMA_QUADS) /* four sigma points a lane: sigma_quads.h */
#include "sigma_quads.h"
SF_READ_INTS(SF_ELEMENT_RHS_ELEMENT_NODES, nodes)
SF_READ_QUADS(SF_ELEMENT_RHS_ELEMENT_REST, rest)
SF_WRITE_QUADS(SF_ELEMENT_RHS_FRAMES, frames)
SF_READ_QUADS(SF_ELEMENT_RHS_X, x)
SF_READ_QUADS(SF_ELEMENT_RHS_V, v)
SF_READ_REALS(SF_ELEMENT_RHS_CONSTANTS, c)
SF_WRITE_QUADS(SF_ELEMENT_RHS_ELEMENT_OUT, element_out)
SF_WRITE_QUADS(SF_ELEMENT_RHS_ELEMENT_DIAGONAL, element_diagonal)

void main() {
  uint S = sf_push.S;
  uint Q = S / 4u;
  uint gid = sf_global_id();
  if (gid >= sf_push.count * Q) return;
  uint e = gid / Q;
  uint q = gid % Q;
  SF_REAL grad[12];
  SF_REAL sigma_lambda;
  SF_REAL sigma_mu;
  uint corner_nodes[4];
  SF_QUAD_ELEMENT(rest, nodes, c, e, q, S, grad, sigma_lambda, sigma_mu, corner_nodes)
  SF_REAL frame[9];
  SF_REAL corner[12];
  SF_REAL force[12];
  SF_REAL product[12];
  SF_GATHER_CORNER_QUADS(x, corner_nodes, q, Q, corner)
  sf_element_rotation(grad, corner, SF_REAL(SF_POLAR_FRAMES), frame);
  sf_frame_third_row(frame);   /* as element_product will make it (ensemble_layout.h) */
  SF_STORE_KEPT_FRAME(frames, e, q, Q, frame)
  sf_element_force(frame, grad, sigma_lambda, sigma_mu, corner, force);
  SF_GATHER_CORNER_QUADS(v, corner_nodes, q, Q, corner)
  sf_element_product(frame, grad, sigma_lambda, sigma_mu, corner, product);
  SF_REAL velocity_factor = SF_QUAD_CONSTANT(c, SF_VELOCITY_FACTOR, q, S);
  for (uint i = 0u; i < 12u; ++i) force[i] -= velocity_factor * product[i];
  SF_STORE_ITEM_QUADS(element_out, e, 12u, q, Q, force)
#if !defined(SF_FACTOR)
  sf_element_diagonal(frame, grad, sigma_lambda, sigma_mu, product);
  SF_STORE_ITEM_QUADS(element_diagonal, e, 12u, q, Q, product)
#endif
}
#else /* a sigma point a lane */
SF_READ_INTS(SF_ELEMENT_RHS_ELEMENT_NODES, nodes)
SF_READ_REALS(SF_ELEMENT_RHS_ELEMENT_REST, rest)
layout(std430, binding = SF_ELEMENT_RHS_FRAMES) restrict writeonly buffer Frames { real frames[]; };
SF_READ_REALS(SF_ELEMENT_RHS_X, x)
SF_READ_REALS(SF_ELEMENT_RHS_V, v)
SF_READ_REALS(SF_ELEMENT_RHS_CONSTANTS, c)
layout(std430, binding = SF_ELEMENT_RHS_ELEMENT_OUT) restrict writeonly buffer ElementOut { real element_out[]; };
layout(std430, binding = SF_ELEMENT_RHS_ELEMENT_DIAGONAL) restrict writeonly buffer ElementDiagonal { real element_diagonal[]; };

void main() {
  uint S = sf_push.S;
  uint gid = sf_global_id();
  if (gid >= sf_push.count * S) return;
  uint e = gid / S;
  uint s = gid % S;
  real grad[12];
  real vlambda;
  real vmu;
  uint corner_nodes[4];
  SF_LOAD_ELEMENT(rest, nodes, e, grad, vlambda, vmu, corner_nodes)
  real sigma_lambda;
  real sigma_mu;
  SF_SIGMA_LAME(rest, c, e, s, S, vlambda, vmu, sigma_lambda, sigma_mu)
  real frame[9];
  real corner[12];
  real force[12];
  real product[12];
  SF_GATHER_CORNERS(x, corner_nodes, s, S, corner)
  sf_element_rotation(grad, corner, real(SF_POLAR_FRAMES), frame);
  sf_frame_third_row(frame);   /* as element_product will make it (ensemble_layout.h) */
  SF_STORE_KEPT_FRAME(frames, e, s, S, frame)
  sf_element_force(frame, grad, sigma_lambda, sigma_mu, corner, force);
  SF_GATHER_CORNERS(v, corner_nodes, s, S, corner)
  sf_element_product(frame, grad, sigma_lambda, sigma_mu, corner, product);
  for (uint i = 0u; i < 12u; ++i) force[i] -= SF_SIGMA_CONSTANT(c, SF_VELOCITY_FACTOR, s, S) * product[i];
  SF_STORE_CORNERS(element_out, e, s, S, force)
#if !defined(SF_FACTOR)
  sf_element_diagonal(frame, grad, sigma_lambda, sigma_mu, product);
  SF_STORE_CORNERS(element_diagonal, e, s, S, product)
#endif
}
#endif
