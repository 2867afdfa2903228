#include "host/opencl/opencl_device.h"

#include <cstdlib>
#include <iostream>
#include <sstream>

namespace sigmafem {

// The kernels of kernels/opencl/, with their includes inlined (cmake/embed_kernel_sources.cmake).
// The text in parts, to be joined in order.
extern const char* const kOpenClKernelSource[];
extern const int kOpenClKernelSource_parts;

namespace {

std::string trimmed(std::string text) {
  while (!text.empty() && (text.back() == '\0' || text.back() == ' ' || text.back() == '\n'))
    text.pop_back();
  return text;
}

std::string device_type_name(cl_device_type type) {
  if (type & CL_DEVICE_TYPE_GPU) return "gpu";
  if (type & CL_DEVICE_TYPE_CPU) return "cpu";
  if (type & CL_DEVICE_TYPE_ACCELERATOR) return "accelerator";
  return "other";
}

// All devices in list order, with their descriptions.
std::vector<std::pair<cl::Device, OpenClDeviceInfo>> enumerate() {
  std::vector<std::pair<cl::Device, OpenClDeviceInfo>> found;
  std::vector<cl::Platform> platforms;
  try {
    cl::Platform::get(&platforms);
  } catch (const cl::Error&) {
    return found;  // CL_PLATFORM_NOT_FOUND_KHR: no ICD installed
  }
  for (const cl::Platform& platform : platforms) {
    std::vector<cl::Device> devices;
    try {
      platform.getDevices(CL_DEVICE_TYPE_ALL, &devices);
    } catch (const cl::Error&) {
      continue;  // a platform without devices
    }
    for (const cl::Device& device : devices) {
      OpenClDeviceInfo info;
      info.index = static_cast<int>(found.size());
      info.platform = trimmed(platform.getInfo<CL_PLATFORM_NAME>());
      info.name = trimmed(device.getInfo<CL_DEVICE_NAME>());
      info.version = trimmed(device.getInfo<CL_DEVICE_VERSION>());
      info.type = device_type_name(device.getInfo<CL_DEVICE_TYPE>());
      info.has_fp64 = device.getInfo<CL_DEVICE_EXTENSIONS>().find("cl_khr_fp64") != std::string::npos;
      info.compute_units = device.getInfo<CL_DEVICE_MAX_COMPUTE_UNITS>();
      info.cache_line = device.getInfo<CL_DEVICE_GLOBAL_MEM_CACHELINE_SIZE>();
      info.global_memory = device.getInfo<CL_DEVICE_GLOBAL_MEM_SIZE>();
      info.max_allocation = device.getInfo<CL_DEVICE_MAX_MEM_ALLOC_SIZE>();
      found.emplace_back(device, info);
    }
  }
  return found;
}

}  // namespace

std::vector<OpenClDeviceInfo> list_opencl_devices() {
  std::vector<OpenClDeviceInfo> list;
  for (const auto& entry : enumerate()) list.push_back(entry.second);
  return list;
}

OpenClDevice::OpenClDevice(int index, Precision precision) : precision_(precision) {
  const auto devices = enumerate();
  if (devices.empty())
    throw DeviceError(
        "no OpenCL platform found: install an OpenCL driver (on Debian, PoCL for the CPU: "
        "apt-get install pocl-opencl-icd) or use --backend cpu");
  if (index < 0 || index >= static_cast<int>(devices.size()))
    throw DeviceError("no OpenCL device " + std::to_string(index) + ": there are " +
                      std::to_string(devices.size()) + " (see `sigmafem devices`)");
  device_ = devices[index].first;
  info_ = devices[index].second;
  if (precision == Precision::double_precision && !info_.has_fp64)
    throw DeviceError("OpenCL device " + std::to_string(index) + " (" + info_.name +
                      ") has no double precision (cl_khr_fp64); use --precision single");
  try {
    context_ = cl::Context(device_);
    profiling_ = std::getenv("SIGMAFEM_OPENCL_PROFILE") != nullptr;
    queue_ = cl::CommandQueue(context_, device_, profiling_ ? CL_QUEUE_PROFILING_ENABLE : 0);
  } catch (const cl::Error& error) {
    throw opencl_failure("setting up OpenCL device " + std::to_string(index), error);
  }
}

void OpenClDevice::build_program(const std::string& defines) {
  const std::string options = std::string("-cl-std=CL1.2") +
                              (precision_ == Precision::double_precision ? " -DSF_USE_DOUBLE" : "") +
                              (defines.empty() ? "" : " " + defines);
  try {
    std::string source;
    for (int part = 0; part < kOpenClKernelSource_parts; ++part) source += kOpenClKernelSource[part];
    program_ = cl::Program(context_, source);
    program_.build({device_}, options.c_str());
  } catch (const cl::Error& error) {
    if (error.err() != CL_BUILD_PROGRAM_FAILURE) throw opencl_failure("building the kernels", error);
    std::string log;
    try {
      log = program_.getBuildInfo<CL_PROGRAM_BUILD_LOG>(device_);
    } catch (const cl::Error&) {
      log = "(no build log)";
    }
    throw DeviceError("the OpenCL kernels failed to build on " + info_.name + " with options '" +
                      options + "'. Build log:\n" + trimmed(log));
  }
}

cl::Kernel OpenClDevice::kernel(const char* name) const {
  try {
    return cl::Kernel(program_, name);
  } catch (const cl::Error& error) {
    throw opencl_failure(std::string("creating kernel ") + name, error);
  }
}

std::string opencl_error_name(int code) {
  switch (code) {
    case CL_DEVICE_NOT_FOUND: return "CL_DEVICE_NOT_FOUND";
    case CL_DEVICE_NOT_AVAILABLE: return "CL_DEVICE_NOT_AVAILABLE";
    case CL_MEM_OBJECT_ALLOCATION_FAILURE: return "CL_MEM_OBJECT_ALLOCATION_FAILURE";
    case CL_OUT_OF_RESOURCES: return "CL_OUT_OF_RESOURCES";
    case CL_OUT_OF_HOST_MEMORY: return "CL_OUT_OF_HOST_MEMORY";
    case CL_BUILD_PROGRAM_FAILURE: return "CL_BUILD_PROGRAM_FAILURE";
    case CL_INVALID_VALUE: return "CL_INVALID_VALUE";
    case CL_INVALID_BUFFER_SIZE: return "CL_INVALID_BUFFER_SIZE";
    case CL_INVALID_KERNEL_NAME: return "CL_INVALID_KERNEL_NAME";
    case CL_INVALID_KERNEL_ARGS: return "CL_INVALID_KERNEL_ARGS";
    case CL_INVALID_ARG_SIZE: return "CL_INVALID_ARG_SIZE";
    case CL_INVALID_WORK_GROUP_SIZE: return "CL_INVALID_WORK_GROUP_SIZE";
    case CL_INVALID_GLOBAL_WORK_SIZE: return "CL_INVALID_GLOBAL_WORK_SIZE";
    default: return "OpenCL error " + std::to_string(code);
  }
}

DeviceError opencl_failure(const std::string& what, const cl::Error& error) {
  std::ostringstream message;
  message << what << ": " << error.what() << " failed with " << opencl_error_name(error.err());
  if (error.err() == CL_MEM_OBJECT_ALLOCATION_FAILURE || error.err() == CL_OUT_OF_RESOURCES ||
      error.err() == CL_OUT_OF_HOST_MEMORY || error.err() == CL_INVALID_BUFFER_SIZE)
    message << " (out of device memory: use fewer sigma points, a coarser mesh or another device)";
  return DeviceError(message.str());
}

void OpenClDevice::record(const cl::Kernel& kernel, const cl::Event& event) {
  if (!profiling_) return;
  event.wait();
  const double ns = static_cast<double>(event.getProfilingInfo<CL_PROFILING_COMMAND_END>() -
                                        event.getProfilingInfo<CL_PROFILING_COMMAND_START>());
  KernelTime& time = profile_[kernel.getInfo<CL_KERNEL_FUNCTION_NAME>()];
  time.seconds += 1e-9 * ns;
  ++time.launches;
}

OpenClDevice::~OpenClDevice() {
  if (!profiling_ || profile_.empty()) return;
  std::cerr << "OpenCL kernel times on " << info_.name << " (SIGMAFEM_OPENCL_PROFILE):\n";
  for (const auto& [name, time] : profile_)
    std::cerr << "  " << name << ": " << time.launches << " launches, " << time.seconds
              << " s, " << 1e6 * time.seconds / static_cast<double>(time.launches)
              << " us each\n";
}

}  // namespace sigmafem
