/* element_product: y_e = R K_e R^T d_e for every element and sigma point, the cost of every
 * CG iteration (as kernels/opencl/element_product.cl, with the sigma point's lambda scale).
 * Each element writes its own 12 outputs; the node kernels sum them in a fixed order: no
 * atomics, the same bits every run.
 * One invocation per (element, sigma), a sigma point whose CG is done skipped; or, compiled
 * with SF_SIGMA_QUADS (element_product_quads), per element and four sigma points. */
#version 450
#extension GL_GOOGLE_include_directive : require
#include "ensemble_layout.h"

layout(local_size_x = SF_ITEMS_PER_GROUP) in;
#if defined(SF_SIGMA_QUADS) /* four sigma points a lane: sigma_quads.h */
#include "sigma_quads.h"
SF_READ_INTS(SF_ELEMENT_PRODUCT_ELEMENT_NODES, nodes)
SF_READ_QUADS(SF_ELEMENT_PRODUCT_ELEMENT_REST, rest)
SF_READ_QUADS(SF_ELEMENT_PRODUCT_FRAMES, frames)
SF_READ_QUADS(SF_ELEMENT_PRODUCT_D, d)
SF_READ_UINTS(SF_ELEMENT_PRODUCT_ACTIVE, active_flags)
SF_WRITE_QUADS(SF_ELEMENT_PRODUCT_ELEMENT_OUT, element_out)
SF_READ_REALS(SF_ELEMENT_PRODUCT_CONSTANTS, c)

void main() {
  uint S = sf_push.S;
  uint Q = S / 4u;
  uint gid = sf_global_id();
  if (gid >= sf_push.count * Q) return;
  uint e = gid / Q;
  uint q = gid % Q;
  bvec4 running = notEqual(uvec4(SF_LOAD(active_flags, 4u * q), SF_LOAD(active_flags, 4u * q + 1u),
                                SF_LOAD(active_flags, 4u * q + 2u), SF_LOAD(active_flags, 4u * q + 3u)),
                          uvec4(0u));
  /* None of the four iterating: nothing to do. Else all four are formed and stored: a sigma
   * point whose CG is done is skipped by every shader that reads them (conjugate_gradient.comp),
   * and a masked store costs llvmpipe a loop over its lanes for each value. */
  if (!any(running)) return;
  SF_REAL grad[12];
  SF_REAL sigma_lambda;
  SF_REAL sigma_mu;
  uint corner_nodes[4];
  SF_QUAD_ELEMENT(rest, nodes, c, e, q, S, grad, sigma_lambda, sigma_mu, corner_nodes)
  SF_REAL frame[9];
  SF_REAL corner[12];
  SF_REAL product[12];
  SF_LOAD_KEPT_FRAME(SF_QUAD, frames, e, q, Q, frame)
  SF_GATHER_CORNER_QUADS(d, corner_nodes, q, Q, corner)
  sf_element_product(frame, grad, sigma_lambda, sigma_mu, corner, product);
  SF_STORE_ITEM_QUADS(element_out, e, 12u, q, Q, product)
}
#else /* a sigma point a lane */
SF_READ_INTS(SF_ELEMENT_PRODUCT_ELEMENT_NODES, nodes)
SF_READ_REALS(SF_ELEMENT_PRODUCT_ELEMENT_REST, rest)
SF_READ_REALS(SF_ELEMENT_PRODUCT_FRAMES, frames)
SF_READ_REALS(SF_ELEMENT_PRODUCT_D, d)
SF_READ_UINTS(SF_ELEMENT_PRODUCT_ACTIVE, active_flags)
layout(std430, binding = SF_ELEMENT_PRODUCT_ELEMENT_OUT) restrict writeonly buffer ElementOut { real element_out[]; };
SF_READ_REALS(SF_ELEMENT_PRODUCT_CONSTANTS, c)

void main() {
  uint S = sf_push.S;
  uint gid = sf_global_id();
  if (gid >= sf_push.count * S) return;
  uint e = gid / S;
  uint s = gid % S;
  if (SF_LOAD(active_flags, s) == 0u) return; /* this sigma point's CG is done */
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
  real product[12];
  SF_LOAD_KEPT_FRAME(SF_LOAD, frames, e, s, S, frame)
  SF_GATHER_CORNERS(d, corner_nodes, s, S, corner)
  sf_element_product(frame, grad, sigma_lambda, sigma_mu, corner, product);
  SF_STORE_CORNERS(element_out, e, s, S, product)
}
#endif
