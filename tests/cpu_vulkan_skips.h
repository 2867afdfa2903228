// Vulkan on the CPU (Mesa's lavapipe, where CI runs the shaders) was 30-40x slower than PoCL
// running the same kernels (bench/RESULTS.md: a liver filter step 134-215 ms against 4.9 ms
// on the 2-core machine at stop 49), and its cases were 46% of the test command's test time;
// 17-21x with the texel reads of stop 50.
// A Vulkan case that only repeats, on the same shaders, what another case checks there is
// skipped on such a device, saying which case covers it; it runs where Vulkan is a GPU
// (bench/gpu_checks.sh runs every device test there), or anywhere with
// SIGMAFEM_TESTS_ALL_VULKAN=1.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

#include "host/vulkan/vulkan_device.h"

namespace sigmafem::test {

// Whether Vulkan device 0 is a CPU implementation and the repeated cases should be skipped.
inline bool skip_repeated_vulkan_cases() {
  const char* all = std::getenv("SIGMAFEM_TESTS_ALL_VULKAN");
  if (all != nullptr && std::string(all) == "1") return false;
  const std::vector<VulkanDeviceInfo> devices = list_vulkan_devices();
  return !devices.empty() && devices[0].type == "cpu";
}

}  // namespace sigmafem::test

// In a test on Vulkan: skips it on a CPU Vulkan device, naming the case that covers it.
#define SIGMAFEM_SKIP_ON_CPU_VULKAN(covered_by)                                                \
  do {                                                                                         \
    if (::sigmafem::test::skip_repeated_vulkan_cases())                                        \
      GTEST_SKIP() << "on a CPU Vulkan device this repeats " << covered_by                     \
                   << " (tests/cpu_vulkan_skips.h; SIGMAFEM_TESTS_ALL_VULKAN=1 runs it)";       \
  } while (false)
