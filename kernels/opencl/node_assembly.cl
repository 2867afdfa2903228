/* node_assembly: per node and sigma point, the element outputs gathered at the node plus the
 * nodal terms of the implicit Euler system (host: host/reference/implicit_euler.h):
 *   node_rhs:     rhs = h (f - (h + a) K v - b M v) and the inverse Jacobi diagonal of A,
 *   node_product: q = A d (the CG product outside CG: the conformance tests' system product).
 * Inside CG the same rows are formed by the per-sigma kernels of conjugate_gradient.cl. */
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
  for (int k = 0; k < 3; ++k) {
    size_t row = ((size_t)3 * n + k) * S + s;
    real xr = x[row];
    real vr = v[row];
    /* elastic force and (h + a) K v from the elements; springs pull towards rest (control
     * springs towards rest + so_shift); the springs' own (h + a) k v term. */
    real f = sf_corner_sum(element_rhs_out, incidence_offsets, incidence, n, k, s, S);
    f -= spring * (xr - rest_positions[3 * n + k]) - control_k[n] * c[SF_SO_SHIFT + k];
    f += mass[n] * c[SF_GRAVITY + k];
    f -= c[SF_VELOCITY_FACTOR] * spring * vr;
    rhs[row] = c[SF_H] * (f - c[SF_RAYLEIGH_MASS] * m * vr);
    real diagonal = sf_corner_sum(element_diagonal, incidence_offsets, incidence, n, k, s, S);
    inverse_diagonal[row] =
        (real)1 / (c[SF_MASS_FACTOR] * m + c[SF_STIFFNESS_FACTOR] * (diagonal + spring));
  }
}

__kernel void node_product(uint S, uint node_count, __global const real* c,
                           __global const int* incidence_offsets, __global const int* incidence,
                           __global const int* ligament_offsets,
                           __global const int* ligament_of_node, __global const real* ligament_k,
                           __global const real* control_k, __global const real* mass,
                           __global const real* d, __global const real* element_out,
                           __global real* q) {
  size_t gid = get_global_id(0);
  if (gid >= (size_t)node_count * S) return;
  uint s = (uint)(gid % S);
  uint n = (uint)(gid / S);
  real spring = sf_node_spring(ligament_offsets, ligament_of_node, ligament_k, control_k, n, s, S);
  real m = sf_solver_mass(mass[n], spring);
  for (int k = 0; k < 3; ++k)
    q[((size_t)3 * n + k) * S + s] = sf_system_row(c, element_out, incidence_offsets, incidence,
                                                   spring, m, d, n, k, s, S);
}
