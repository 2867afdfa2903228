#include "host/vulkan/spirv_bindings.h"

#include <cstring>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace sigmafem {
namespace {

// The few SPIR-V opcodes, decorations and enumerants that say what a binding is (the SPIR-V
// specification, sections 3.32 and 3.14).
constexpr std::uint32_t kMagic = 0x07230203;
constexpr std::uint32_t kOpTypeInt = 21, kOpTypeFloat = 22, kOpTypeImage = 25;
constexpr std::uint32_t kOpTypeSampledImage = 27, kOpTypePointer = 32, kOpVariable = 59;
constexpr std::uint32_t kOpName = 5, kOpDecorate = 71;
constexpr std::uint32_t kDecorationBinding = 33, kDecorationDescriptorSet = 34;
constexpr std::uint32_t kDimBuffer = 5;
constexpr std::uint32_t kImageFormatRgba32f = 1, kImageFormatR32f = 3;

}  // namespace

std::map<std::uint32_t, SpirvBinding> spirv_bindings(const std::uint32_t* words, std::size_t count) {
  if (words == nullptr || count < 5 || words[0] != kMagic)
    throw std::invalid_argument("not a SPIR-V module (bad header)");
  std::unordered_map<std::uint32_t, std::uint32_t> binding_of, set_of;
  std::unordered_map<std::uint32_t, std::uint32_t> pointee;       // pointer type -> type
  std::unordered_map<std::uint32_t, std::uint32_t> variable_type; // variable -> pointer type
  std::unordered_map<std::uint32_t, std::uint32_t> sampled_image; // sampled image -> image
  std::unordered_map<std::uint32_t, std::uint32_t> buffer_image;  // buffer image -> sampled type
  std::unordered_map<std::uint32_t, std::uint32_t> image_format;  // buffer image -> its format
  std::unordered_map<std::uint32_t, SpirvBinding> scalar_kind;    // 32-bit scalar types
  std::unordered_map<std::uint32_t, std::string> name_of;          // OpName: id -> name
  for (std::size_t at = 5; at < count;) {
    const std::uint32_t length = words[at] >> 16, opcode = words[at] & 0xffffu;
    if (length == 0 || at + length > count)
      throw std::invalid_argument("SPIR-V instruction at word " + std::to_string(at) +
                                  " runs past the module's end");
    const std::uint32_t* operand = words + at + 1;
    const std::uint32_t operands = length - 1;
    if (opcode == kOpName && operands >= 2)   // the id, then a nul-terminated string
      name_of[operand[0]] = std::string(reinterpret_cast<const char*>(operand + 1),
                                        strnlen(reinterpret_cast<const char*>(operand + 1),
                                                4 * (operands - 1)));
    else if (opcode == kOpDecorate && operands >= 3 && operand[1] == kDecorationBinding)
      binding_of[operand[0]] = operand[2];
    else if (opcode == kOpDecorate && operands >= 3 && operand[1] == kDecorationDescriptorSet)
      set_of[operand[0]] = operand[2];
    else if (opcode == kOpTypeFloat && operands >= 2 && operand[1] == 32)
      scalar_kind[operand[0]] = SpirvBinding::float_texels;
    else if (opcode == kOpTypeInt && operands >= 3 && operand[1] == 32)
      scalar_kind[operand[0]] = operand[2] ? SpirvBinding::int_texels : SpirvBinding::uint_texels;
    else if (opcode == kOpTypeImage && operands >= 3 && operand[2] == kDimBuffer) {
      buffer_image[operand[0]] = operand[1];
      if (operands >= 8) image_format[operand[0]] = operand[7];
    }
    else if (opcode == kOpTypeSampledImage && operands >= 2)
      sampled_image[operand[0]] = operand[1];
    else if (opcode == kOpTypePointer && operands >= 3)
      pointee[operand[0]] = operand[2];
    else if (opcode == kOpVariable && operands >= 2)
      variable_type[operand[1]] = operand[0];
    at += length;
  }
  // What a variable's pointee is: a sampled buffer image of 32-bit texels (or of four floats,
  // by its name), a buffer image itself (a storage texel buffer, of r32f or rgba32f only), or
  // else storage.
  auto find = [](const auto& map, std::uint32_t key, std::uint32_t& value) {
    const auto it = map.find(key);
    if (it == map.end()) return false;
    value = it->second;
    return true;
  };
  std::map<std::uint32_t, SpirvBinding> result;
  for (const auto& [variable, binding] : binding_of) {
    std::uint32_t set = 0;
    if (find(set_of, variable, set) && set != 0) continue;
    SpirvBinding kind = SpirvBinding::storage_buffer;
    std::uint32_t pointer = 0, type = 0, image = 0, texel = 0;
    if (find(variable_type, variable, pointer) && find(pointee, pointer, type) &&
        find(sampled_image, type, image) && find(buffer_image, image, texel)) {
      const auto it = scalar_kind.find(texel);
      if (it != scalar_kind.end()) kind = it->second;
      const auto name = name_of.find(variable);
      const std::string rgba = "_rgba";
      if (kind == SpirvBinding::float_texels && name != name_of.end() && name->second.size() > rgba.size() &&
          name->second.compare(name->second.size() - rgba.size(), rgba.size(), rgba) == 0)
        kind = SpirvBinding::float4_texels;
    } else if (find(variable_type, variable, pointer) && find(pointee, pointer, type) &&
               find(buffer_image, type, texel)) {
      std::uint32_t format = 0;
      if (!find(image_format, type, format) || (format != kImageFormatR32f && format != kImageFormatRgba32f))
        throw std::invalid_argument("binding " + std::to_string(binding) +
                                    " is a storage texel buffer of a format other than r32f or rgba32f");
      kind = format == kImageFormatR32f ? SpirvBinding::float_image : SpirvBinding::float4_image;
    }
    result[binding] = kind;
  }
  return result;
}

}  // namespace sigmafem
