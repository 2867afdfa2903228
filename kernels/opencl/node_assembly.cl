/* node_assembly: per node and sigma point, the element outputs gathered at the node plus the
 * nodal terms of the implicit Euler system (host: host/reference/implicit_euler.h):
 *   node_rhs:     rhs = h (f - (h + a) K v - b M v) and the inverse Jacobi diagonal of A,
 *   node_product: q = A d, in every CG iteration (work-items as in element_product.cl: on a
 *                 CPU a node for all sigma points, vectorised over them, summing the element
 *                 chunks' copies instead of gathering element outputs). */
#include "ensemble_layout.h"
#include "node_rows.h"

__kernel void node_rhs(uint S, uint node_count, __global const real* c,
                       __global const int* incidence_offsets, __global const int* incidence,
                       __global const int* ligament_offsets, __global const int* ligament_of_node,
                       __global const real* ligament_k, __global const real* control_k,
                       __global const real* mass, __global const real* rest_positions,
                       __global const real* x, __global const real* v,
                       __global const real* element_out, __global const real* element_diagonal,
                       __global real* rhs, __global real* inverse_diagonal) {
  size_t gid = get_global_id(0);
  if (gid >= (size_t)node_count * S) return;
  uint s = (uint)(gid % S);
  uint n = (uint)(gid / S);
  real spring;
  SF_NODE_SPRING(ligament_offsets, ligament_of_node, ligament_k, control_k, n, s, S, spring)
  real m = sf_solver_mass(mass[n], spring);
  struct SfNodeConstants at;
  SF_LOAD_NODE_CONSTANTS(c, s, S, at)
  real f_elements[3];
  SF_CORNER_SUMS(element_out, incidence_offsets, incidence, n, s, S, f_elements)
#if !SF_FACTOR /* the Jacobi diagonal, which a factor does not need */
  real diagonal[3];
  SF_CORNER_SUMS(element_diagonal, incidence_offsets, incidence, n, s, S, diagonal)
#endif
  real u[3];
  for (int k = 0; k < 3; ++k) u[k] = x[((size_t)3 * n + k) * S + s] - rest_positions[3 * n + k];
  real law = sf_ligament_law(spring, control_k[n], u, at.inverse_d0_squared);
  SF_UNROLL
  for (int k = 0; k < 3; ++k) {
    size_t row = ((size_t)3 * n + k) * S + s;
    rhs[row] = sf_node_rhs_row(at, k, f_elements[k], u[k], v[row], spring, control_k[n], law,
                               mass[n], m);
#if !SF_FACTOR
    inverse_diagonal[row] = sf_node_inverse_diagonal(at, diagonal[k], spring, m);
#endif
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
    for (uint b = 0; b < SF_SIGMA_BLOCK; ++b)
      q[row + b] = SF_SYSTEM_ROW(c, first + b, S, sum[b], spring[b], m[b], d[row + b]);
  }
}
