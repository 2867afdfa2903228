/* ensemble_layout.h: how the Vulkan ensemble lays out its arrays: the same layout as the
 * OpenCL ensemble (kernels/opencl/ensemble_layout.h, ARCHITECTURE.md "The ensemble on a
 * device"), sigma index innermost:
 *   per-dof     x[(3 * node + axis) * S + s]
 *   per-element frames[(9 * e + i) * S + s],  corner outputs [(12 * e + i) * S + s]
 * Shared data (rest shape, element rest state, mass) is stored once for all sigma points.
 * Work-items of the element and node kernels: gid = item * S + s (one (item, sigma) pair per
 * invocation; llvmpipe runs 8 invocations in one SIMD register, a GPU a warp).
 *
 * Buffers are std430 storage buffers in descriptor set 0; a shader's binding numbers follow
 * the order of the buffer arguments of the OpenCL kernel of the same name. The scalar
 * arguments (S, the item count, the CG cap, p) are push constants (SfPush, the same 16
 * bytes for every shader: host/vulkan/vulkan_ensemble.cpp, struct PushConstants).
 * Indices are 32-bit: the host checks every buffer against maxStorageBufferRange. */
#ifndef SIGMAFEM_VULKAN_ENSEMBLE_LAYOUT_H
#define SIGMAFEM_VULKAN_ENSEMBLE_LAYOUT_H

#ifdef SF_USE_DOUBLE
#  define SF_REAL double
#endif

#include "element.h"
#include "step_constants.h"

/* GLSL has no typedef. */
#define real SF_REAL

layout(push_constant) uniform SfPush {
  uint S;               /* sigma points */
  uint count;           /* elements, nodes, rows or observed nodes: the kernel's items */
  int max_iterations;   /* CG iteration cap (cg_iteration) */
  uint p;               /* the filter's parameters (recenter) */
} sf_push;

/* Invocations per work-group of the element and node kernels (the host dispatches
 * ceil(items / SF_ITEMS_PER_GROUP) groups, in two dimensions past 65535). */
#define SF_ITEMS_PER_GROUP 64

/* The flattened global index over a 2-D grid of work-groups (x fastest), in shaders with
 * layout(local_size_x = SF_ITEMS_PER_GROUP). Not gl_WorkGroupSize: glslang takes it as 1
 * in a function defined before the shader's local_size declaration. */
uint sf_global_id() {
  return (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * SF_ITEMS_PER_GROUP +
         gl_LocalInvocationID.x;
}

/* The element rest state, 16 numbers per element: grad[12], vlambda, vmu, two unused. */
#define SF_REST_STRIDE 16u

/* Loads element e's rest state and node indices from buffers `rest_` and `nodes_`. */
#define SF_LOAD_ELEMENT(rest_, nodes_, e, grad, vlambda, vmu, corner_nodes)     \
  for (uint i_ = 0u; i_ < 12u; ++i_) grad[i_] = rest_[(e) * SF_REST_STRIDE + i_]; \
  vlambda = rest_[(e) * SF_REST_STRIDE + 12u];                                    \
  vmu = rest_[(e) * SF_REST_STRIDE + 13u];                                        \
  for (uint c_ = 0u; c_ < 4u; ++c_) corner_nodes[c_] = uint(nodes_[4u * (e) + c_]);

/* Gathers a per-dof array's values at an element's four corners for sigma point s. */
#define SF_GATHER_CORNERS(v_, corner_nodes, s, S, out_)                 \
  for (uint c_ = 0u; c_ < 4u; ++c_)                                     \
    for (uint k_ = 0u; k_ < 3u; ++k_)                                   \
      out_[3u * c_ + k_] = v_[(3u * corner_nodes[c_] + k_) * (S) + (s)];

/* Stores 12 corner values of element e for sigma point s. */
#define SF_STORE_CORNERS(out_, e, s, S, values)                          \
  for (uint i_ = 0u; i_ < 12u; ++i_) out_[(12u * (e) + i_) * (S) + (s)] = values[i_];

#endif /* SIGMAFEM_VULKAN_ENSEMBLE_LAYOUT_H */
