// The options that choose where simulations run, shared by `estimate`, `generate` and `demo`:
// --backend auto|cpu|opencl|vulkan, --device N, --precision single|double, --preconditioner.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "host/common/device_options.h"

namespace sigmafem::cli {

struct BackendChoice {
  std::string backend = "auto";   // `generate` sets "cpu" before add_backend_options
  int device = 0;
  std::string precision = "single";
  std::string preconditioner = "auto";
  std::size_t device_memory_mib = 0;   // DeviceOptions::device_memory, in MiB; 0: the device's
  DeviceOptions device_options() const;
};

void add_backend_options(CLI::App* command, BackendChoice& choice);

}  // namespace sigmafem::cli
