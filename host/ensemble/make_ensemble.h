// make_ensemble: the one place that turns a back-end name ("cpu", "opencl", "vulkan") into an Ensemble,
// for the command line, the tests and the benchmarks.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "filter/ensemble.h"
#include "host/common/device_error.h"
#include "host/common/device_options.h"
#include "host/mesh/observed_points.h"
#include "host/model/model.h"

namespace sigmafem {

// The back ends this build has, in the order `--backend` lists them.
std::vector<std::string> available_backends();

// "auto" is resolve_backend()'s choice (host/ensemble/choose_backend.h). Throws InputError
// for an unknown name, DeviceError when the device cannot run it.
// The CPU back end takes only `options.preconditioner` (automatic: the factors);
// a device back end refuses Preconditioner::factorised with an InputError.
std::unique_ptr<Ensemble> make_ensemble(const std::string& backend, const Model& model,
                                        const std::vector<int>& estimated,
                                        const ObservedPoints& observed, int sigma_count,
                                        const DeviceOptions& options = {});

}  // namespace sigmafem
