// The Vulkan ensemble's shaders, compiled from kernels/vulkan/ to SPIR-V at build time and
// embedded in the program (cmake/compile_glsl.cmake): one entry per shader and variant.
#pragma once

#include <cstddef>
#include <cstdint>

namespace sigmafem {

struct EmbeddedShader {
  const char* name;              // the entry shader: "element_product", "cg_start", ...
  bool double_precision;         // compiled with -DSF_USE_DOUBLE
  bool texel_reads;              // compiled with -DSF_TEXEL_READS: read-only arrays are
                                 // uniform texel buffers (kernels/vulkan/ensemble_layout.h)
  const std::uint32_t* words;    // the SPIR-V module
  std::size_t word_count;
};

extern const EmbeddedShader kVulkanShaders[];
extern const std::size_t kVulkanShaderCount;

}  // namespace sigmafem
