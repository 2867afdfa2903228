// choose_backend: what `--backend auto` runs an ensemble on, by the speeds measured in
// bench/RESULTS.md. A GPU (device 0 of OpenCL, else of Vulkan) from kGpuPairs element-sigma
// pairs on: on the H200 the 4768-tetrahedron liver at S = 16 (76 288 pairs) stepped in
// 8-12 ms against 30 ms for the CPU back end on 2 cores, while the 596-tetrahedron liver's
// filter step (S = 4, 2 384 pairs) took 2.9-3.8 ms there against 1.6 ms on 2 CPU cores, and
// S = 16 on it (9 536 pairs) was even. OpenCL before Vulkan: it was ahead on the large meshes
// (117k box 75 against 90 ms, 38k filter step 23.5 against 61 ms). Without a GPU, OpenCL on
// a CPU device (PoCL) up to kCpuDeviceElements tetrahedra or from kCpuDevicePairs pairs: with
// its shared factor (stop 44) it stepped the liver ahead of the CPU back end on 2 cores
// (filter step 1.2-1.4 against 1.4-1.6 ms; 596 x 16 2.1 against 4.7 ms; 4768 x 4 8.3 against
// 21 ms; 4768 x 16 23 against 47 ms) and the 38k liver at S = 16 (336 against 2333 ms, where
// the CPU back end's S factors outgrow its memory budget and it shares one), but not the
// 38k liver's filter step at S = 4 (374 against 268 ms: the shared factor takes 5.7 CG
// iterations there, the CPU back end's own factors 2-3). Nor when the sigma points differ by
// estimated Young's moduli of regions (issue 19) and OpenCL would share one factor among them:
// the mean sigma point's preconditions them less well (10-13 CG iterations against 3.5-4.8
// for the CPU back end's own), and the liver's filter step with 13 and 61 region moduli took
// 8.9 and 56 ms on OpenCL against 7.8 and 27 on the CPU back end (bench/RESULTS.md, stop 49).
// Where each sigma point gets its own factor on OpenCL (from 16 sigma points, up to
// kOwnFactorPairs, estimated) it took 5.6 and 24 ms. Between the bounds OpenCL still, where its
// shared factor is corrected for each sigma point's springs (every parameter a ligament's, and
// spring_correction_fits): the 38k liver's filter step then took 1.8 CG iterations and 71-79 ms
// against the CPU back end's 97-100 ms (stop 51). Otherwise the CPU back end.
#pragma once

#include <cstddef>
#include <string>

#include "host/model/estimated_parameters.h"
#include "host/model/model.h"

namespace sigmafem {

// Element x sigma-point pairs in one product from which a GPU is chosen.
constexpr long long kGpuPairs = 16384;
// Without a GPU, OpenCL on a CPU device is chosen over the CPU back end up to this many
// tetrahedra (between the 4768 measured faster on it and the 38144 measured slower at S = 4)
// or from this many element-sigma pairs (between 38144 x 4, slower, and 38144 x 16, faster).
constexpr long long kCpuDeviceElements = 16384;
constexpr long long kCpuDevicePairs = 262144;
// Up to this many element-sigma pairs, and from kOwnFactorsFromSigmaPoints, OpenCL's sigma
// points get factors of their own (DeviceOptions::own_factors_bytes; L has 44 entries per
// tetrahedron on the 596 liver, 94 on the 4768 one): the 596-tetrahedron liver at S = 65, the
// largest ensemble measured with them.
constexpr long long kOwnFactorPairs = 596 * 65;

// Device 0 of each device back end when it is a GPU: its name, "" when it is not a GPU or
// there is none; and OpenCL's device 0 when it is a CPU device (PoCL).
struct GpuPresence {
  std::string opencl;
  std::string vulkan;
  std::string opencl_cpu;
};
GpuPresence find_gpus();

struct BackendDecision {
  std::string backend;   // "cpu", "opencl" or "vulkan"
  std::string reason;    // one line: why
};

// The choice for `elements` tetrahedra and `sigma_count` sigma points, of which
// `estimated_regions` parameters are regions' Young's moduli, on these GPUs; `spring_rows`:
// the rows of the estimated ligaments' nodes (estimated_spring_rows).
BackendDecision choose_backend(const GpuPresence& gpus, long long elements, int sigma_count,
                               int estimated_regions = 0, std::size_t spring_rows = 0);

// `backend` as given ("cpu", "opencl", "vulkan": reason "given"), or "auto" decided by
// choose_backend on this machine's GPUs for the model and what is estimated.
BackendDecision resolve_backend(const std::string& backend, const Model& model, int sigma_count,
                                const EstimatedParameters& estimated);

}  // namespace sigmafem
