/* node_assembly.h: what every node-side shader needs (node_assembly.comp,
 * conjugate_gradient.comp's cg_start), as kernels/opencl/node_assembly.h: the gather of
 * element outputs at a node's incident corners in a fixed order (deterministic, no atomics)
 * and the node's springs and mass in the implicit Euler system
 *   A = (1 + h b) M + h (h + a) K,   K = elastic tangent + springs on the diagonal.
 * GLSL cannot pass a buffer to a function, so these shaders declare the shared buffers at
 * the bindings below (their OpenCL argument order) and the gather over a buffer that differs
 * between them is a macro. */
#ifndef SIGMAFEM_VULKAN_NODE_ASSEMBLY_H
#define SIGMAFEM_VULKAN_NODE_ASSEMBLY_H

#include "ensemble_layout.h"

layout(std430, binding = 0) restrict readonly buffer C { real c[]; };
layout(std430, binding = 1) restrict readonly buffer IncidenceOffsets { int incidence_offsets[]; };
layout(std430, binding = 2) restrict readonly buffer Incidence { int incidence[]; };
layout(std430, binding = 3) restrict readonly buffer LigamentOffsets { int ligament_offsets[]; };
layout(std430, binding = 4) restrict readonly buffer LigamentOfNode { int ligament_of_node[]; };
layout(std430, binding = 5) restrict readonly buffer LigamentK { real ligament_k[]; };
layout(std430, binding = 6) restrict readonly buffer ControlK { real control_k[]; };
layout(std430, binding = 7) restrict readonly buffer Mass { real mass[]; };

/* sum = sum over node n's incident corners of a per-corner output, axis k, sigma s. */
#define SF_CORNER_SUM(values_, n, k, s, S, sum)                                     \
  sum = real(0);                                                                    \
  for (int i_ = incidence_offsets[n]; i_ < incidence_offsets[(n) + 1u]; ++i_)        \
    sum += values_[(3u * uint(incidence[i_]) + (k)) * (S) + (s)];

/* The spring stiffness on node n for sigma point s (ligaments and control). */
real sf_node_spring(uint n, uint s, uint S) {
  real k = control_k[n];
  for (int i = ligament_offsets[n]; i < ligament_offsets[n + 1u]; ++i)
    k += ligament_k[uint(ligament_of_node[i]) * S + s];
  return k;
}

/* A node that no tetrahedron uses and no spring holds has a unit placeholder mass, so that
 * its rows of A are not zero (as in ImplicitEulerSystem). */
real sf_solver_mass(real m, real spring) {
  return (m == real(0) && spring == real(0)) ? real(1) : m;
}

/* Row 3 n + k of A d for sigma point s, from the gathered element products Kd_elements. */
real sf_system_row(real Kd_elements, real spring, real m, real d_row) {
  return c[SF_STIFFNESS_FACTOR] * (Kd_elements + spring * d_row) + c[SF_MASS_FACTOR] * m * d_row;
}

#endif /* SIGMAFEM_VULKAN_NODE_ASSEMBLY_H */
