/* node_assembly: per node and sigma point, the element outputs gathered at the node plus the
 * nodal terms of the implicit Euler system (host: host/reference/implicit_euler.h):
 *   node_rhs:     rhs = h (f - (h + a) K v - b M v) and the inverse Jacobi diagonal of A,
 *   node_product: q = A d, in every CG iteration (work-items as in element_product.cl: on a
 *                 CPU a node for all sigma points, vectorised over them, summing the element
 *                 chunks' copies instead of gathering element outputs). */
#include "node_assembly.h"

__kernel void node_rhs(uint S, uint node_count, __global const real* c,
                       __global const int* incidence_offsets, __global const int* incidence,
                       __global const int* ligament_offsets, __global const int* ligament_of_node,
                       __global const real* ligament_k, __global const real* control_k,
                       __global const real* mass, __global const real* rest_positions,
                       __global const real* x, __global const real* v,
                       __global const real* element_rhs_out, __global const real* element_diagonal,
                       __global real* rhs, __global real* inverse_diagonal) {
  size_t gid = get_global_id(0);
  if (gid >= (size_t)node_count * S) return;
  uint s = (uint)(gid % S);
  uint n = (uint)(gid / S);
  real spring = sf_node_spring(ligament_offsets, ligament_of_node, ligament_k, control_k, n, s, S);
  real m = sf_solver_mass(mass[n], spring);
  /* This sigma point's loads (step_constants.h): at[k * S] is load k. */
  __global const real* at = c + SF_STEP_CONSTANTS + s;
  /* The ligament law's explicit part, k u |u|^2/d0^2 (its linear part k u is in spring): 0
   * for the linear law. */
  real u2 = (real)0;
  for (int k = 0; k < 3; ++k) {
    real u = x[((size_t)3 * n + k) * S + s] - rest_positions[3 * n + k];
    u2 += u * u;
  }
  real law = (spring - control_k[n]) * u2 * at[SF_INVERSE_D0_SQUARED * S];
  real young = at[SF_YOUNG_SCALE * S];
  SF_UNROLL
  for (int k = 0; k < 3; ++k) {
    size_t row = ((size_t)3 * n + k) * S + s;
    real xr = x[row];
    real vr = v[row];
    /* elastic force and (h + a) K v from the elements; springs pull towards rest (control
     * springs towards rest + so_shift); the springs' own (h + a) k v term. */
    real f = young * sf_corner_sum(element_rhs_out, incidence_offsets, incidence, n, k, s, S);
    real u = xr - rest_positions[3 * n + k];
    f -= spring * u - control_k[n] * at[(SF_SO_SHIFT + k) * S];
    f -= law * u;
    f += mass[n] * at[(SF_GRAVITY + k) * S];
    f -= at[SF_VELOCITY_FACTOR * S] * spring * vr;
    rhs[row] = c[SF_H] * (f - at[SF_RAYLEIGH_MASS * S] * m * vr);
    real diagonal = young * sf_corner_sum(element_diagonal, incidence_offsets, incidence, n, k, s, S);
    inverse_diagonal[row] =
        (real)1 / (at[SF_MASS_FACTOR * S] * m + at[SF_STIFFNESS_FACTOR * S] * (diagonal + spring));
  }
}

__kernel void node_product(uint S, uint node_count, __global const real* restrict c,
                           __global const int* restrict incidence_offsets,
                           __global const int* restrict incidence,
                           __global const int* restrict ligament_offsets,
                           __global const int* restrict ligament_of_node,
                           __global const real* restrict ligament_k,
                           __global const real* restrict control_k,
                           __global const real* restrict mass, __global const real* restrict d,
                           __global const real* restrict element_out, __global real* restrict q) {
  uint n;
  uint first;
  if (!sf_block_item(get_global_id(0), S, node_count, &n, &first)) return;
  /* Loops over the sigma block innermost, over contiguous data: the compiler vectorises them. */
  real spring[SF_SIGMA_BLOCK];
  real m[SF_SIGMA_BLOCK];
  for (uint b = 0; b < SF_SIGMA_BLOCK; ++b) spring[b] = control_k[n];
  for (int i = ligament_offsets[n]; i < ligament_offsets[n + 1]; ++i) {
    __global const real* k = ligament_k + (size_t)ligament_of_node[i] * S + first;
    for (uint b = 0; b < SF_SIGMA_BLOCK; ++b) spring[b] += k[b];
  }
  for (uint b = 0; b < SF_SIGMA_BLOCK; ++b) m[b] = sf_solver_mass(mass[n], spring[b]);
  SF_UNROLL
  for (int k = 0; k < 3; ++k) {
    size_t row = ((size_t)3 * n + k) * S + first;
    real sum[SF_SIGMA_BLOCK];
    for (uint b = 0; b < SF_SIGMA_BLOCK; ++b) sum[b] = (real)0;
#if SF_ELEMENT_CHUNKS > 0
    /* The chunks' copies of K d (element_product.cl), in chunk order. */
    for (uint chunk = 0; chunk < SF_ELEMENT_CHUNKS; ++chunk) {
      __global const real* out = element_out + chunk * ((size_t)3 * node_count * S) + row;
      for (uint b = 0; b < SF_SIGMA_BLOCK; ++b) sum[b] += out[b];
    }
#else
    for (int i = incidence_offsets[n]; i < incidence_offsets[n + 1]; ++i) {
      __global const real* out = element_out + ((size_t)3 * incidence[i] + k) * S + first;
      for (uint b = 0; b < SF_SIGMA_BLOCK; ++b) sum[b] += out[b];
    }
#endif
    for (uint b = 0; b < SF_SIGMA_BLOCK; ++b) {
      uint s = first + b;
      real db = d[row + b];
      q[row + b] = SF_SIGMA_CONSTANT(c, SF_STIFFNESS_FACTOR, s, S) *
                       (SF_SIGMA_CONSTANT(c, SF_YOUNG_SCALE, s, S) * sum[b] + spring[b] * db) +
                   SF_SIGMA_CONSTANT(c, SF_MASS_FACTOR, s, S) * m[b] * db;
    }
  }
}
