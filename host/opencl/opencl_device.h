// The OpenCL devices of this machine and one of them made ready for the ensemble: platform
// and device discovery (`sigmafem devices`), a context and an in-order queue, and the
// ensemble's program built once per run from the embedded kernels (kernels/opencl/). Drivers
// cache compiled programs themselves (PoCL in ~/.cache/pocl, NVIDIA in ~/.nv/ComputeCache),
// so a second run does not pay the compile again.
#pragma once

#define CL_HPP_TARGET_OPENCL_VERSION 120
#define CL_HPP_MINIMUM_OPENCL_VERSION 120
#define CL_HPP_ENABLE_EXCEPTIONS
#include <CL/opencl.hpp>

#include <map>
#include <string>
#include <vector>

#include "host/common/device_error.h"
#include "host/common/device_options.h"

namespace sigmafem {

struct OpenClDeviceInfo {
  int index = 0;                    // position in the list, over all platforms
  std::string platform;
  std::string name;
  std::string version;              // the device's OpenCL version string
  std::string type;                 // "cpu", "gpu", "accelerator", "other"
  bool has_fp64 = false;            // cl_khr_fp64: --precision double is available
  unsigned compute_units = 0;
  unsigned cache_line = 0;          // bytes of a global memory cache line (0: not said)
  unsigned long long global_memory = 0;     // bytes
  unsigned long long max_allocation = 0;    // bytes, the largest single buffer
};

// Every device of every platform, in platform order. Empty when there is no platform (no
// ICD installed), never an exception for that.
std::vector<OpenClDeviceInfo> list_opencl_devices();

// A device with its context, queue and the ensemble's program.
class OpenClDevice {
 public:
  // Throws DeviceError: no platform, no device `index`, or no fp64 for double precision.
  OpenClDevice(int index, Precision precision);
  ~OpenClDevice();
  OpenClDevice(const OpenClDevice&) = delete;
  OpenClDevice& operator=(const OpenClDevice&) = delete;

  const OpenClDeviceInfo& info() const { return info_; }
  Precision precision() const { return precision_; }
  std::size_t real_size() const { return sigmafem::real_size(precision_); }
  cl::Context& context() { return context_; }
  cl::CommandQueue& queue() { return queue_; }
  // Builds the embedded kernels with these extra -D options (once, before kernel()).
  // Throws DeviceError with the build log when they fail to build.
  void build_program(const std::string& defines);
  cl::Kernel kernel(const char* name) const;
  // With SIGMAFEM_OPENCL_PROFILE set, adds the kernel's device time (waiting for it) to a
  // table printed on stderr when the device is released: where the time goes.
  void record(const cl::Kernel& kernel, const cl::Event& event);

 private:
  OpenClDeviceInfo info_;
  Precision precision_;
  cl::Device device_;
  cl::Context context_;
  cl::CommandQueue queue_;
  cl::Program program_;
  struct KernelTime {
    double seconds = 0.0;
    long long launches = 0;
  };
  bool profiling_ = false;
  std::map<std::string, KernelTime> profile_;
};

// The name of an OpenCL error code ("CL_OUT_OF_RESOURCES"), for messages.
std::string opencl_error_name(int code);

// A DeviceError for a failed OpenCL call, saying what was being done.
DeviceError opencl_failure(const std::string& what, const cl::Error& error);

}  // namespace sigmafem
