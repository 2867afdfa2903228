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
 * products are linear in it). Work-items as in element_product.cl: on a CPU a contiguous
 * chunk of the elements per compute unit, else one per element and block of sigma points. */
#include "ensemble_layout.h"

/* The scenario's rotation method (material.rotation) is fixed for an ensemble and comes as a
 * build option (OpenClEnsemble): chosen at run time from the step constants, the branch kept
 * PoCL from vectorising the loop over the sigma points (bench/RESULTS.md, stop 46). */
#ifndef SF_POLAR_FRAMES
#  define SF_POLAR_FRAMES 0
#endif

/* Element e's outputs for the sigma points first .. first + SF_SIGMA_BLOCK - 1: each sigma
 * point's numbers into private arrays first, then the stores, each a loop over the block on
 * contiguous data (as element_chunk.h does), so that the compiler vectorises the first loop. */
static inline __attribute__((always_inline)) void sf_element_rhs_block(
    uint e, uint first, uint S, __global const int* restrict nodes,
    __global const real* restrict rest, __global real* restrict frames,
    __global const real* restrict x, __global const real* restrict v,
    __global const real* restrict c, __global real* restrict element_out,
    __global real* restrict element_diagonal) {
  real grad[12];
  real vlambda;
  real vmu;
  uint corner_nodes[4];
  SF_LOAD_ELEMENT(rest, nodes, e, grad, vlambda, vmu, corner_nodes)
  real block_frames[9][SF_SIGMA_BLOCK];
  real block_rhs[12][SF_SIGMA_BLOCK];
#if !SF_FACTOR
  real block_diagonal[12][SF_SIGMA_BLOCK];
#endif
  for (uint b = 0; b < SF_SIGMA_BLOCK; ++b) {
    const uint s = first + b;
    real sigma_lambda;
    real sigma_mu;
    SF_SIGMA_LAME(rest, c, e, s, S, vlambda, vmu, sigma_lambda, sigma_mu)
    real frame[9];
    real corner[12];
    real force[12];
    real product[12];
    SF_GATHER_CORNERS(x, corner_nodes, s, S, corner)
#if SF_POLAR_FRAMES
    sf_element_polar_frame(grad, corner, frame);
#else
    sf_element_frame(corner, frame);
#endif
    sf_element_force(frame, grad, sigma_lambda, sigma_mu, corner, force);
    SF_GATHER_CORNERS(v, corner_nodes, s, S, corner)
    sf_element_product(frame, grad, sigma_lambda, sigma_mu, corner, product);
    SF_UNROLL
    for (int i = 0; i < 12; ++i)
      block_rhs[i][b] = force[i] - SF_SIGMA_CONSTANT(c, SF_VELOCITY_FACTOR, s, S) * product[i];
    SF_UNROLL
    for (int i = 0; i < 9; ++i) block_frames[i][b] = frame[i];
#if !SF_FACTOR /* the Jacobi diagonal, which a factor does not need */
    sf_element_diagonal(frame, grad, sigma_lambda, sigma_mu, product);
    SF_UNROLL
    for (int i = 0; i < 12; ++i) block_diagonal[i][b] = product[i];
#endif
  }
  SF_UNROLL
  for (uint i = 0; i < 9u; ++i)
    for (uint b = 0; b < SF_SIGMA_BLOCK; ++b)
      frames[(SF_INDEX(9u) * e + i) * S + first + b] = block_frames[i][b];
  SF_UNROLL
  for (uint i = 0; i < 12u; ++i)
    for (uint b = 0; b < SF_SIGMA_BLOCK; ++b)
      element_out[(SF_INDEX(12u) * e + i) * S + first + b] = block_rhs[i][b];
#if !SF_FACTOR
  SF_UNROLL
  for (uint i = 0; i < 12u; ++i)
    for (uint b = 0; b < SF_SIGMA_BLOCK; ++b)
      element_diagonal[(SF_INDEX(12u) * e + i) * S + first + b] = block_diagonal[i][b];
#endif
}

__kernel void element_rhs(uint S, uint element_count, __global const int* restrict nodes,
                          __global const real* restrict rest, __global real* restrict frames,
                          __global const real* restrict x, __global const real* restrict v,
                          __global const real* restrict c, __global real* restrict element_out,
                          __global real* restrict element_diagonal) {
#if SF_ELEMENT_CHUNKS > 0
  const uint chunk = (uint)get_global_id(0);
  if (chunk >= SF_ELEMENT_CHUNKS) return;
  const uint end = sf_chunk_start(chunk + 1, element_count);
  for (uint e = sf_chunk_start(chunk, element_count); e < end; ++e)
    sf_element_rhs_block(e, 0, S, nodes, rest, frames, x, v, c, element_out, element_diagonal);
#else
  uint e;
  uint first;
  if (sf_block_item(get_global_id(0), S, element_count, &e, &first))
    sf_element_rhs_block(e, first, S, nodes, rest, frames, x, v, c, element_out, element_diagonal);
#endif
}
