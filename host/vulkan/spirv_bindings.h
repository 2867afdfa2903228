// What each binding of a SPIR-V compute module's descriptor set 0 is, read from the module
// itself, so that the host lays out and fills a shader's descriptor set as the shader
// declares it: the shaders compiled with texel reads (kernels/vulkan/ensemble_layout.h) read
// some arrays through uniform texel buffers, the others through storage buffers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>

namespace sigmafem {

enum class SpirvBinding {
  storage_buffer,   // a std430 buffer block (or anything that is not a texel buffer)
  float_texels,     // uniform samplerBuffer: R32_SFLOAT texels
  float4_texels,    // uniform samplerBuffer named *_rgba: R32G32B32A32_SFLOAT, four floats a
                    // texel (a sampled buffer's SPIR-V type has no format to say so)
  int_texels,       // uniform isamplerBuffer: R32_SINT
  uint_texels,      // uniform usamplerBuffer: R32_UINT (in a float64 shader, R32G32_UINT:
                    // a double's two halves; kernels/vulkan/ensemble_layout.h)
  float_image,      // imageBuffer, r32f: a storage texel buffer (read and written)
  float4_image,     // imageBuffer, rgba32f: a storage texel buffer of four floats a texel
};

// Whether a binding of this kind is a storage texel buffer.
inline bool storage_texels(SpirvBinding kind) {
  return kind == SpirvBinding::float_image || kind == SpirvBinding::float4_image;
}

// Binding number -> kind, for the variables of descriptor set 0 that carry a Binding
// decoration (a float samplerBuffer is float4_texels when its OpName ends in "_rgba"). Throws
// std::invalid_argument when the words are not a well-formed SPIR-V module (no magic number,
// an instruction that runs past the end, a zero word count) or declare a storage texel buffer
// of a format other than r32f or rgba32f.
std::map<std::uint32_t, SpirvBinding> spirv_bindings(const std::uint32_t* words, std::size_t count);

}  // namespace sigmafem
