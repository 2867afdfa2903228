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

// The arithmetic of a device ensemble: float32 by default; float64 where the device has it.
enum class Precision { single, double_precision };

// How a device back end runs its CG solve: a few launches per iteration (products over all
// sigma points at once, on every core), the whole solve in one launch (no launch cost per
// iteration, one core), or the back end's choice by mesh size and S.
enum class SolveLaunch { automatic, per_iteration, whole_solve };

// Which device and precision a device back end uses (`--device N --precision single|double`).
struct DeviceOptions {
  int device = 0;                   // index in `sigmafem devices`' list for the back end
  Precision precision = Precision::single;
  SolveLaunch solve_launch = SolveLaunch::automatic;
};

}  // namespace sigmafem
