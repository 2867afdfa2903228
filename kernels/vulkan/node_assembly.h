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

/* sum[k] = sum over node n's incident corners of a per-corner output, axis k, sigma s, for
 * the three axes in one pass: each corner index is loaded once, not once per axis (on
 * lavapipe every load of a lane-varying address is a scalar gather: this pass is 4 loads
 * per corner instead of 9). Each axis is summed in the incidence order: the same bits. */
#define SF_CORNER_SUMS(values_, n, s, S, sum)                         \
  sum[0] = real(0);                                                   \
  sum[1] = real(0);                                                   \
  sum[2] = real(0);                                                   \
  {                                                                   \
    int end_ = incidence_offsets[(n) + 1u];                           \
    for (int i_ = incidence_offsets[n]; i_ < end_; ++i_) {            \
      uint base_ = 3u * uint(incidence[i_]) * (S) + (s);              \
      sum[0] += values_[base_];                                       \
      sum[1] += values_[base_ + (S)];                                 \
      sum[2] += values_[base_ + 2u * (S)];                            \
    }                                                                 \
  }

/* The spring stiffness on node n for sigma point s (ligaments and control). */
real sf_node_spring(uint n, uint s, uint S) {
  real k = control_k[n];
  int end = ligament_offsets[n + 1u];
  for (int i = ligament_offsets[n]; i < end; ++i)
    k += ligament_k[uint(ligament_of_node[i]) * S + s];
  return k;
}

/* A node that no tetrahedron uses and no spring holds has a unit placeholder mass, so that
 * its rows of A are not zero (as in ImplicitEulerSystem). */
real sf_solver_mass(real m, real spring) {
  return (m == real(0) && spring == real(0)) ? real(1) : m;
}

/* Row 3 n + k of A d for sigma point s, from the gathered element products Kd_elements; the
 * factors of A and Young's modulus scale are the sigma point's (step_constants.h). */
real sf_system_row(real Kd_elements, real spring, real m, real d_row, uint s, uint S) {
  return SF_SIGMA_CONSTANT(c, SF_STIFFNESS_FACTOR, s, S) *
             (SF_SIGMA_CONSTANT(c, SF_YOUNG_SCALE, s, S) * Kd_elements + spring * d_row) +
         SF_SIGMA_CONSTANT(c, SF_MASS_FACTOR, s, S) * m * d_row;
}

#endif /* SIGMAFEM_VULKAN_NODE_ASSEMBLY_H */
