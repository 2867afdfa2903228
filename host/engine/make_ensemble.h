// make_ensemble: the one place that turns a back-end name ("cpu", "opencl", "vulkan") into an
// ensemble, for the command line, the tests and the benchmarks. It sits above the back ends
// (host/ensemble, host/opencl, host/vulkan), which know nothing of it.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "host/common/device_error.h"
#include "host/common/device_options.h"
#include "host/ensemble/effect_ensemble.h"
#include "host/ensemble/simulation_ensemble.h"
#include "host/mesh/observed_points.h"
#include "host/model/estimated_parameters.h"
#include "host/model/model.h"

namespace sigmafem {

// The back ends this build has, in the order `--backend` lists them.
std::vector<std::string> available_backends();

// "auto" is resolve_backend()'s choice (host/engine/choose_backend.h). Throws InputError
// for an unknown name, DeviceError when the device cannot run it.
// The CPU back end takes only `options.preconditioner` (automatic: the factors); OpenCL
// has its shared factor on a CPU device (automatic: there, not on a GPU; factorised on a GPU
// is a DeviceError), Vulkan refuses factorised with an InputError.
std::unique_ptr<SimulationEnsemble> make_ensemble(const std::string& backend, const Model& model,
                                                  const EstimatedParameters& estimated,
                                                  const ObservedPoints& observed, int sigma_count,
                                                  const DeviceOptions& options = {});

// The preconditioner that `backend` (not "auto") runs CG with under `options` on `model`:
// "factorised", "multigrid" or "jacobi", for the reports. For OpenCL it asks the device's type.
std::string preconditioner_used(const std::string& backend, const DeviceOptions& options, const Model& model);

// The ensemble of `model` on `backend` with the candidate `effects` estimated (EffectEnsemble):
// the ligament of every ligament effect is appended to the model and to `estimated` first.
std::unique_ptr<EffectEnsemble> make_effect_ensemble(const std::string& backend, Model model,
                                                     EstimatedParameters estimated,
                                                     const ObservedPoints& observed, int sigma_count,
                                                     const DeviceOptions& options,
                                                     const std::vector<std::string>& effects);

}  // namespace sigmafem
