// choose_backend: what `--backend auto` runs an ensemble on, by the speeds measured in
// bench/RESULTS.md. A GPU (device 0 of OpenCL, else of Vulkan) from kGpuPairs element-sigma
// pairs on: on the H200 the 4768-tetrahedron liver at S = 16 (76 288 pairs) stepped in
// 8-12 ms against 30 ms for the CPU back end on 2 cores, while the 596-tetrahedron liver's
// filter step (S = 4, 2 384 pairs) took 2.9-3.8 ms there against 1.6 ms on 2 CPU cores, and
// S = 16 on it (9 536 pairs) was even. OpenCL before Vulkan: it was ahead on the large meshes
// (117k box 75 against 90 ms, 38k filter step 23.5 against 61 ms). Otherwise the CPU back end:
// with its sparse factors (3-4 CG iterations a step) it beat OpenCL on PoCL on every liver
// case measured on 2 cores (filter step 1.6 against 2.7 ms, 4768 liver at S = 16 30 against
// 64 ms).
#pragma once

#include <string>

#include "host/model/model.h"

namespace sigmafem {

// Element x sigma-point pairs in one product from which a GPU is chosen.
constexpr long long kGpuPairs = 16384;

// Device 0 of each device back end when it is a GPU: its name, "" when it is not a GPU or
// there is none.
struct GpuPresence {
  std::string opencl;
  std::string vulkan;
};
GpuPresence find_gpus();

struct BackendDecision {
  std::string backend;   // "cpu", "opencl" or "vulkan"
  std::string reason;    // one line: why
};

// The choice for `elements` tetrahedra and `sigma_count` sigma points on these GPUs.
BackendDecision choose_backend(const GpuPresence& gpus, long long elements, int sigma_count);

// `backend` as given ("cpu", "opencl", "vulkan": reason "given"), or "auto" decided by
// choose_backend on this machine's GPUs for the model.
BackendDecision resolve_backend(const std::string& backend, const Model& model, int sigma_count);

}  // namespace sigmafem
