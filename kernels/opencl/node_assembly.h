/* node_assembly.h: what every node-side kernel needs (node_assembly.cl, conjugate_gradient.cl):
 * the gather of element outputs at a node's incident corners, in a fixed order (deterministic,
 * no atomics), and the node's springs and mass in the implicit Euler system
 *   A = (1 + h b) M + h (h + a) K,   K = elastic tangent + springs on the diagonal.
 * Springs: a node's stiffness is the sum of its ligaments' per-node stiffness (which differs
 * between sigma points: ligament_k[l * S + s]) and its control stiffness (shared). */
#ifndef SIGMAFEM_NODE_ASSEMBLY_H
#define SIGMAFEM_NODE_ASSEMBLY_H

#include "ensemble_layout.h"

/* Sum over node n's incident corners of a per-corner element output, axis k, sigma s. */
static inline real sf_corner_sum(__global const real* corner_values,
                                 __global const int* incidence_offsets,
                                 __global const int* incidence, uint n, int k, uint s, uint S) {
  real sum = (real)0;
  for (int i = incidence_offsets[n]; i < incidence_offsets[n + 1]; ++i)
    sum += corner_values[((size_t)3 * incidence[i] + k) * S + s];
  return sum;
}

/* The spring stiffness on node n for sigma point s (ligaments and control). */
static inline real sf_node_spring(__global const int* ligament_offsets,
                                  __global const int* ligament_of_node,
                                  __global const real* ligament_k, __global const real* control_k,
                                  uint n, uint s, uint S) {
  real k = control_k[n];
  for (int i = ligament_offsets[n]; i < ligament_offsets[n + 1]; ++i)
    k += ligament_k[(size_t)ligament_of_node[i] * S + s];
  return k;
}

/* A node that no tetrahedron uses and no spring holds has a unit placeholder mass, so that
 * its rows of A are not zero (as in ImplicitEulerSystem). */
static inline real sf_solver_mass(real mass, real spring) {
  return (mass == (real)0 && spring == (real)0) ? (real)1 : mass;
}

/* Row `row` (= 3 n + k) of A d for sigma point s, from the element products already
 * gathered-ready in element_out (element_product.cl), the spring and the solver mass. */
static inline real sf_system_row(__global const real* c, __global const real* element_out,
                                 __global const int* incidence_offsets,
                                 __global const int* incidence, real spring, real m,
                                 __global const real* d, uint n, int k, uint s, uint S) {
  size_t row = ((size_t)3 * n + k) * S + s;
  real Kd = sf_corner_sum(element_out, incidence_offsets, incidence, n, k, s, S) + spring * d[row];
  return c[SF_STIFFNESS_FACTOR] * Kd + c[SF_MASS_FACTOR] * m * d[row];
}

#endif /* SIGMAFEM_NODE_ASSEMBLY_H */
