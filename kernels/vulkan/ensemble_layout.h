/* ensemble_layout.h: what every Vulkan shader includes: the layout, slots and push constants
 * every back end shares (kernels/shared/device_layout.h) in GLSL's terms, and the index
 * helpers over its buffers. Buffers are std430 storage buffers in descriptor set 0, bound at
 * device_layout.h's slots (the CG shaders' bindings are their own: conjugate_gradient.comp).
 * Indices are 32-bit: the host checks every buffer against maxStorageBufferRange. */
#ifndef SIGMAFEM_VULKAN_ENSEMBLE_LAYOUT_H
#define SIGMAFEM_VULKAN_ENSEMBLE_LAYOUT_H

#ifdef SF_USE_DOUBLE
#  define SF_REAL double
#endif

#include "device_layout.h"
#include "element.h"
#include "step_constants.h"

/* GLSL has no typedef. */
#define real SF_REAL

#define SF_UINT_FIELD(name) uint name;
#define SF_INT_FIELD(name) int name;
layout(push_constant) uniform SfPush { SF_PUSH_CONSTANTS(SF_UINT_FIELD, SF_INT_FIELD) } sf_push;

/* The host dispatches ceil(items / SF_ITEMS_PER_GROUP) groups, in two dimensions past 65535. */

/* The flattened global index over a 2-D grid of work-groups (x fastest), in shaders with
 * layout(local_size_x = SF_ITEMS_PER_GROUP). Not gl_WorkGroupSize: glslang takes it as 1
 * in a function defined before the shader's local_size declaration. */
uint sf_global_id() {
  return (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * SF_ITEMS_PER_GROUP +
         gl_LocalInvocationID.x;
}

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
