/* element_rhs: the rotation step and each element's part of the implicit Euler right-hand
 * side and of the Jacobi diagonal, per sigma point, in one pass over the elements (host:
 * element_frames, ImplicitEulerSystem::right_hand_side and ::diagonal):
 *   frame  = the element's frame at x      (QR or polar, element.h; stored: every CG
 *                                           product of the step uses it)
 *   rhs_e  = f_e(x) - (h + a) K_e v_e      (elastic force and the stiffness-damping product;
 *                                           h + a per sigma point, step_constants.h)
 *   diag_e = diag(R K_e R^T)
 * The node kernel (node_assembly.cl) sums them over the incident elements and adds the
 * nodal terms (mass, springs, gravity) and a sigma point's Young's modulus scale (the
 * products are linear in it). Work-items as in element_product.cl. */
#include "ensemble_layout.h"

__kernel void element_rhs(uint S, uint element_count, __global const int* restrict nodes,
                          __global const real* restrict rest, __global real* restrict frames,
                          __global const real* restrict x, __global const real* restrict v,
                          __global const real* restrict c, __global real* restrict element_out,
                          __global real* restrict element_diagonal) {
  uint e;
  uint first;
  if (!sf_block_item(get_global_id(0), S, element_count, &e, &first)) return;
  real grad[12];
  real vlambda;
  real vmu;
  uint corner_nodes[4];
  SF_LOAD_ELEMENT(rest, nodes, e, grad, vlambda, vmu, corner_nodes)
  const real vlambda_model = vlambda;
  for (uint b = 0; b < SF_SIGMA_BLOCK; ++b) {
    uint s = first + b;
    vlambda = vlambda_model * SF_SIGMA_CONSTANT(c, SF_LAMBDA_SCALE, s, S);
    real frame[9];
    real corner[12];
    real force[12];
    real product[12];
    SF_GATHER_CORNERS(x, corner_nodes, s, S, corner)
    sf_element_rotation(grad, corner, c[SF_POLAR_ROTATION], frame);
    SF_STORE_FRAME(frames, e, s, S, frame)
    sf_element_force(frame, grad, vlambda, vmu, corner, force);
    SF_GATHER_CORNERS(v, corner_nodes, s, S, corner)
    sf_element_product(frame, grad, vlambda, vmu, corner, product);
    SF_UNROLL
    for (int i = 0; i < 12; ++i) force[i] -= SF_SIGMA_CONSTANT(c, SF_VELOCITY_FACTOR, s, S) * product[i];
    SF_STORE_CORNERS(element_out, e, s, S, force)
#if !SF_FACTOR /* the Jacobi diagonal, which a factor does not need */
    sf_element_diagonal(frame, grad, vlambda, vmu, product);
    SF_STORE_CORNERS(element_diagonal, e, s, S, product)
#endif
  }
}
