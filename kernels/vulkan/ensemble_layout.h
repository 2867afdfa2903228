/* ensemble_layout.h: what every Vulkan shader includes: the layout, slots and push constants
 * every back end shares (kernels/shared/device_layout.h) in GLSL's terms, and the index
 * helpers over its buffers. Buffers are bound in descriptor set 0 at device_layout.h's slots
 * (the CG shaders' bindings are their own: conjugate_gradient.comp): std430 storage buffers,
 * or texel buffers for what a shader only reads (below). Indices are 32-bit: the host checks
 * every buffer against maxStorageBufferRange. */
#ifndef SIGMAFEM_VULKAN_ENSEMBLE_LAYOUT_H
#define SIGMAFEM_VULKAN_ENSEMBLE_LAYOUT_H

/* SF_SCALAR a buffer's real; SF_REAL the arithmetic's (dialect.h, element.h): the same, or
 * in the sigma-quad shaders (SF_SIGMA_QUADS: kernels/vulkan/sigma_quads.h) a vector of
 * four sigma points. */
#ifdef SF_USE_DOUBLE
#  define SF_SCALAR double
#  define SF_SCALAR4 dvec4
#else
#  define SF_SCALAR float
#  define SF_SCALAR4 vec4
#endif
#ifdef SF_SIGMA_QUADS
#  define SF_REAL SF_SCALAR4
#else
#  define SF_REAL SF_SCALAR
#endif

#include "device_layout.h"
#include "element.h"
#include "step_constants.h"

/* GLSL has no typedef. */
#define real SF_SCALAR

/* Vulkan keeps an element's frame as its first two rows, 6 of device_layout.h's 9 numbers: a
 * storage-buffer store costs llvmpipe a loop over its lanes (without the third row's stores
 * element_rhs took ~12% less on the 4768 liver at S = 16; bench/RESULTS.md, stop 61), and the
 * third row is their cross product (sf_frame_third_row), made again where a frame is read.
 * element_rhs makes its frame so before using it too: every shader of a step sees the same one.
 * The buffer holds the 6 alone (since stop 63; a third less of the frames' memory). */
/* (s, S): a sigma point and S; in the sigma-quad shaders a quad q and Q (sigma_quads.h), read
 * with LOAD = SF_QUAD. */
#define SF_FRAME_ROWS_KEPT SF_FRAME_TWO_ROWS
#define SF_LOAD_KEPT_FRAME(LOAD, frames, e, s, S, frame)                                    \
  SF_UNROLL for (uint i_ = 0u; i_ < SF_FRAME_ROWS_KEPT; ++i_)                               \
    frame[i_] = LOAD(frames, (SF_FRAME_ROWS_KEPT * (e) + i_) * (S) + (s));                  \
  sf_frame_third_row(frame);
#define SF_STORE_KEPT_FRAME(frames, e, s, S, frame) \
  SF_UNROLL for (uint i_ = 0u; i_ < SF_FRAME_ROWS_KEPT; ++i_) frames[(SF_FRAME_ROWS_KEPT * (e) + i_) * (S) + (s)] = frame[i_];

/* The arrays a shader only reads, declared with SF_READ_REALS/INTS/UINTS(binding, name) and
 * read with SF_LOAD(name, index) (dialect.h): storage buffers, or, in the shaders compiled
 * with SF_TEXEL_READS (the CPU form, for lavapipe), uniform texel buffers. llvmpipe turns
 * every storage-buffer load at an address that differs between its 8 lanes into a loop over
 * the lanes with a branch and a bounds check each; a texel fetch is one gather with a bounds
 * mask: 3-5x faster loads there (bench/RESULTS.md, stop 50). The host binds each binding by
 * what the SPIR-V declares (host/vulkan/spirv_bindings.h): a samplerBuffer is R32_SFLOAT
 * texels, an isamplerBuffer R32_SINT, a usamplerBuffer R32_UINT, or in a float64 shader
 * R32G32_UINT, a double's two halves (no texel format holds a 64-bit float), so float64
 * shaders read their unsigned arrays as int. */
#if defined(SF_TEXEL_READS)
#  define SF_READ_INTS(slot, name) layout(binding = slot) uniform isamplerBuffer name;
int sf_texel(isamplerBuffer b, uint i) { return texelFetch(b, int(i)).x; }
#  if defined(SF_USE_DOUBLE)
#    define SF_READ_REALS(slot, name) layout(binding = slot) uniform usamplerBuffer name;
#    define SF_READ_UINTS(slot, name) layout(binding = slot) uniform isamplerBuffer name;
double sf_texel(usamplerBuffer b, uint i) { return packDouble2x32(texelFetch(b, int(i)).xy); }
#  else
#    define SF_READ_REALS(slot, name) layout(binding = slot) uniform samplerBuffer name;
#    define SF_READ_UINTS(slot, name) layout(binding = slot) uniform usamplerBuffer name;
float sf_texel(samplerBuffer b, uint i) { return texelFetch(b, int(i)).x; }
uint sf_texel(usamplerBuffer b, uint i) { return texelFetch(b, int(i)).x; }
#  endif
#else
#  define SF_READ_REALS(slot, name) \
    layout(std430, binding = slot) restrict readonly buffer name##_buffer { real name[]; };
#  define SF_READ_INTS(slot, name) \
    layout(std430, binding = slot) restrict readonly buffer name##_buffer { int name[]; };
#  define SF_READ_UINTS(slot, name) \
    layout(std430, binding = slot) restrict readonly buffer name##_buffer { uint name[]; };
#endif

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

#endif /* SIGMAFEM_VULKAN_ENSEMBLE_LAYOUT_H */
