// DeviceError: the exception type for a compute device that cannot do what was asked (no
// OpenCL platform or Vulkan device, a kernel that fails to build, out of device memory).
// Its message says what failed and what to do, so the command line can print it as is.
#pragma once

#include <stdexcept>
#include <string>

namespace sigmafem {

class DeviceError : public std::runtime_error {
 public:
  explicit DeviceError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace sigmafem
