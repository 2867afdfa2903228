/* node_assembly.h: what every node-side kernel needs (node_assembly.cl, conjugate_gradient.cl):
 * the gather of element outputs at a node's incident corners, in a fixed order (deterministic,
 * no atomics), and the node's springs and mass in the implicit Euler system
 *   A = (1 + h b) M + h (h + a) K,   K = elastic tangent + springs on the diagonal.
 * Springs: a node's stiffness is the sum of its ligaments' per-node stiffness (which differs
 * between sigma points: ligament_k[l * S + s]) and its control stiffness (shared). The
 * factors of A, the damping and Young's modulus scale are per sigma point
 * (SF_SIGMA_CONSTANT, step_constants.h): the elements' K d is scaled where it is gathered. */
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

#endif /* SIGMAFEM_NODE_ASSEMBLY_H */
