// `sigmafem devices`: the compute devices this machine offers to the device back ends.
#include <iostream>

#include "host/cli/commands.h"
#include "host/opencl/opencl_device.h"

namespace sigmafem::cli {

Action add_devices_command(CLI::App& app) {
  app.add_subcommand("devices", "List the OpenCL platforms and devices (--device N picks one)");
  return []() {
    const std::vector<OpenClDeviceInfo> devices = list_opencl_devices();
    std::cout << "OpenCL (--backend opencl):\n";
    if (devices.empty()) {
      std::cout << "  no OpenCL platform found: install a driver (on Debian, PoCL for the CPU: "
                   "apt-get install pocl-opencl-icd)\n";
      return 0;
    }
    for (const OpenClDeviceInfo& d : devices) {
      std::cout << "  --device " << d.index << ": " << d.name << " (" << d.type << ", platform "
                << d.platform << ", " << d.version << ", " << d.compute_units
                << " compute units, " << (d.global_memory >> 20) << " MiB, largest buffer "
                << (d.max_allocation >> 20) << " MiB, "
                << (d.has_fp64 ? "double precision" : "single precision only") << ")\n";
    }
    return 0;
  };
}

}  // namespace sigmafem::cli
