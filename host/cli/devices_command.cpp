// `sigmafem devices`: the compute devices this machine offers to the device back ends, OpenCL
// first, then Vulkan; `--device N` indexes the list of the chosen back end.
#include <iostream>

#include "host/cli/commands.h"
#include "host/opencl/opencl_device.h"
#include "host/vulkan/vulkan_device.h"

namespace sigmafem::cli {
namespace {

void print_opencl_devices() {
  const std::vector<OpenClDeviceInfo> devices = list_opencl_devices();
  std::cout << "OpenCL (--backend opencl):\n";
  if (devices.empty()) {
    std::cout << "  no OpenCL platform found: install a driver (on Debian, PoCL for the CPU: "
                 "apt-get install pocl-opencl-icd)\n";
    return;
  }
  for (const OpenClDeviceInfo& d : devices) {
    std::cout << "  --device " << d.index << ": " << d.name << " (" << d.type << ", platform "
              << d.platform << ", " << d.version << ", " << d.compute_units
              << " compute units, " << (d.global_memory >> 20) << " MiB, largest buffer "
              << (d.max_allocation >> 20) << " MiB, "
              << (d.has_fp64 ? "double precision" : "single precision only") << ")\n";
  }
}

void print_vulkan_devices() {
  std::string why;
  const std::vector<VulkanDeviceInfo> devices = list_vulkan_devices(&why);
  std::cout << "Vulkan (--backend vulkan):\n";
  if (devices.empty()) {
    std::cout << "  " << why << "\n";
    return;
  }
  for (const VulkanDeviceInfo& d : devices) {
    std::cout << "  --device " << d.index << ": " << d.name << " (" << d.type << ", Vulkan "
              << d.api_version << ", " << (d.memory >> 20) << " MiB, largest buffer "
              << (d.max_buffer >> 20) << " MiB, "
              << (d.has_fp64 ? "double precision" : "single precision only") << ")\n";
  }
}

}  // namespace

Action add_devices_command(CLI::App& app) {
  app.add_subcommand("devices",
                     "List the OpenCL and Vulkan devices (--device N picks one of a back end)");
  return []() {
    print_opencl_devices();
    print_vulkan_devices();
    return 0;
  };
}

}  // namespace sigmafem::cli
