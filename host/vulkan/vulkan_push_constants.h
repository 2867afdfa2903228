// The scalar arguments of every Vulkan shader: SF_PUSH_CONSTANTS (kernels/shared/device_layout.h)
// as the 16 bytes of push constants the host records with each dispatch.
#pragma once

#include <cstdint>

#include "device_layout.h"
#include "host/vulkan/vulkan_device.h"

namespace sigmafem {

#define SF_HOST_UINT(name) std::uint32_t name = 0;
#define SF_HOST_INT(name) std::int32_t name = 0;
struct VulkanPushConstants {
  SF_PUSH_CONSTANTS(SF_HOST_UINT, SF_HOST_INT)
};
#undef SF_HOST_UINT
#undef SF_HOST_INT
static_assert(sizeof(VulkanPushConstants) == VulkanDevice::kPushConstantBytes,
              "SF_PUSH_CONSTANTS: the shaders' 16 bytes of push constants");

}  // namespace sigmafem
