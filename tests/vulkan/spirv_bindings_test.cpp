// The bindings a shader declares, read from its SPIR-V (host/vulkan/spirv_bindings.h): the
// embedded element_product in its variants, and modules that are not SPIR-V.
#include "host/vulkan/spirv_bindings.h"

#include <gtest/gtest.h>

#include <cstring>
#include <stdexcept>
#include <vector>

#include "device_layout.h"
#include "host/vulkan/vulkan_shaders.h"

namespace sigmafem {
namespace {

const EmbeddedShader& embedded(const char* name, bool double_precision, bool texel_reads) {
  for (std::size_t i = 0; i < kVulkanShaderCount; ++i) {
    const EmbeddedShader& shader = kVulkanShaders[i];
    if (std::strcmp(shader.name, name) == 0 && shader.double_precision == double_precision &&
        shader.texel_reads == texel_reads)
      return shader;
  }
  throw std::logic_error(std::string("no embedded shader ") + name);
}

TEST(SpirvBindings, TheTexelVariantReadsItsReadOnlyArraysAsTexelsOfTheirType) {
  const EmbeddedShader& shader = embedded("element_product", false, true);
  const auto bindings = spirv_bindings(shader.words, shader.word_count);
  EXPECT_EQ(bindings.at(SF_ELEMENT_PRODUCT_ELEMENT_NODES), SpirvBinding::int_texels);
  EXPECT_EQ(bindings.at(SF_ELEMENT_PRODUCT_ELEMENT_REST), SpirvBinding::float_texels);
  EXPECT_EQ(bindings.at(SF_ELEMENT_PRODUCT_FRAMES), SpirvBinding::float_texels);
  EXPECT_EQ(bindings.at(SF_ELEMENT_PRODUCT_D), SpirvBinding::float_texels);
  EXPECT_EQ(bindings.at(SF_ELEMENT_PRODUCT_ACTIVE), SpirvBinding::uint_texels);
  EXPECT_EQ(bindings.at(SF_ELEMENT_PRODUCT_CONSTANTS), SpirvBinding::float_texels);
  // What the shader writes stays a storage buffer.
  EXPECT_EQ(bindings.at(SF_ELEMENT_PRODUCT_ELEMENT_OUT), SpirvBinding::storage_buffer);
  // In float64 the reals are unsigned pairs (R32G32_UINT) and the unsigned flags ints.
  const EmbeddedShader& doubles = embedded("element_product", true, true);
  const auto double_bindings = spirv_bindings(doubles.words, doubles.word_count);
  EXPECT_EQ(double_bindings.at(SF_ELEMENT_PRODUCT_ELEMENT_REST), SpirvBinding::uint_texels);
  EXPECT_EQ(double_bindings.at(SF_ELEMENT_PRODUCT_ACTIVE), SpirvBinding::int_texels);
  EXPECT_EQ(double_bindings.at(SF_ELEMENT_PRODUCT_ELEMENT_OUT), SpirvBinding::storage_buffer);
}

// The sigma-quad element shaders (kernels/vulkan/sigma_quads.h) read their per-sigma arrays
// and the rest state four floats a texel: samplerBuffers named *_rgba; the constants, nodes
// and flags one a texel. In float64 (no texel of four doubles) the scalar kinds.
TEST(SpirvBindings, SamplerBuffersNamedRgbaAreTexelsOfFourFloats) {
  const EmbeddedShader& shader = embedded("element_product_quads", false, true);
  const auto bindings = spirv_bindings(shader.words, shader.word_count);
  EXPECT_EQ(bindings.at(SF_ELEMENT_PRODUCT_ELEMENT_REST), SpirvBinding::float4_texels);
  EXPECT_EQ(bindings.at(SF_ELEMENT_PRODUCT_FRAMES), SpirvBinding::float4_texels);
  EXPECT_EQ(bindings.at(SF_ELEMENT_PRODUCT_D), SpirvBinding::float4_texels);
  EXPECT_EQ(bindings.at(SF_ELEMENT_PRODUCT_CONSTANTS), SpirvBinding::float_texels);
  EXPECT_EQ(bindings.at(SF_ELEMENT_PRODUCT_ELEMENT_NODES), SpirvBinding::int_texels);
  EXPECT_EQ(bindings.at(SF_ELEMENT_PRODUCT_ACTIVE), SpirvBinding::uint_texels);
  EXPECT_EQ(bindings.at(SF_ELEMENT_PRODUCT_ELEMENT_OUT), SpirvBinding::storage_buffer);
  const EmbeddedShader& doubles = embedded("element_product_quads", true, true);
  EXPECT_EQ(spirv_bindings(doubles.words, doubles.word_count).at(SF_ELEMENT_PRODUCT_FRAMES),
            SpirvBinding::uint_texels);
}

TEST(SpirvBindings, TheStorageVariantsReadStorageBuffersOnly) {
  for (const bool double_precision : {false, true}) {
    const EmbeddedShader& shader = embedded("element_product", double_precision, false);
    const auto bindings = spirv_bindings(shader.words, shader.word_count);
    EXPECT_EQ(bindings.size(), 7u);
    for (const auto& [binding, kind] : bindings)
      EXPECT_EQ(kind, SpirvBinding::storage_buffer) << "binding " << binding;
  }
}

TEST(SpirvBindings, EveryShaderHasATexelVariantWithTheSameBindings) {
  for (std::size_t i = 0; i < kVulkanShaderCount; ++i) {
    const EmbeddedShader& shader = kVulkanShaders[i];
    if (shader.texel_reads) continue;
    const EmbeddedShader& texel = embedded(shader.name, shader.double_precision, true);
    const auto storage = spirv_bindings(shader.words, shader.word_count);
    const auto texels = spirv_bindings(texel.words, texel.word_count);
    ASSERT_EQ(storage.size(), texels.size()) << shader.name;
    for (const auto& [binding, kind] : storage) EXPECT_EQ(texels.count(binding), 1u) << shader.name;
  }
}

// factor_solve's work vector and blocks in float32 are rgba32f imageBuffers (storage texel
// buffers of four floats a texel); in float64 storage buffers. A storage texel buffer of
// another format than r32f or rgba32f is refused (the host makes views of those only).
TEST(SpirvBindings, TheFactorSolvesWorkVectorIsAStorageTexelBufferInFloat32) {
  for (const bool texel_reads : {false, true}) {
    const EmbeddedShader& shader = embedded("factor_solve", false, texel_reads);
    const auto kinds = spirv_bindings(shader.words, shader.word_count);
    EXPECT_EQ(kinds.at(SF_FACTOR_SOLVE_WORK), SpirvBinding::float4_image);
    EXPECT_EQ(kinds.at(SF_FACTOR_SOLVE_FORWARD_BLOCKS), SpirvBinding::float4_image);
    EXPECT_EQ(kinds.at(SF_FACTOR_SOLVE_Z), SpirvBinding::storage_buffer);
    const EmbeddedShader& doubles = embedded("factor_solve", true, texel_reads);
    EXPECT_EQ(spirv_bindings(doubles.words, doubles.word_count).at(SF_FACTOR_SOLVE_WORK), SpirvBinding::storage_buffer);
  }
  const EmbeddedShader& shader = embedded("factor_solve", false, true);
  std::vector<std::uint32_t> words(shader.words, shader.words + shader.word_count);
  bool changed = false;
  for (std::size_t at = 5; at < words.size(); at += words[at] >> 16) {
    const bool storage_image = (words[at] & 0xffffu) == 25u && (words[at] >> 16) >= 9 &&
                               words[at + 3] == 5u && words[at + 7] == 2u;   // OpTypeImage, Buffer, Sampled 2
    if (storage_image) {
      words[at + 8] = 6u;   // Rg32f
      changed = true;
    }
  }
  ASSERT_TRUE(changed);
  EXPECT_THROW(spirv_bindings(words.data(), words.size()), std::invalid_argument);
}

TEST(SpirvBindings, WordsThatAreNotSpirvAreRefused) {
  const std::vector<std::uint32_t> garbage = {0xdeadbeef, 1, 2, 3, 4, 5};
  EXPECT_THROW(spirv_bindings(garbage.data(), garbage.size()), std::invalid_argument);
  EXPECT_THROW(spirv_bindings(nullptr, 0), std::invalid_argument);
  // A header, then an instruction of 9 words with 2 left.
  const std::vector<std::uint32_t> truncated = {0x07230203, 0x00010000, 0, 10, 0, (9u << 16) | 71u, 1};
  EXPECT_THROW(spirv_bindings(truncated.data(), truncated.size()), std::invalid_argument);
  // An instruction of length 0 would never end.
  const std::vector<std::uint32_t> endless = {0x07230203, 0x00010000, 0, 10, 0, 71u};
  EXPECT_THROW(spirv_bindings(endless.data(), endless.size()), std::invalid_argument);
}

}  // namespace
}  // namespace sigmafem
