// The estimation job shared by `sigmafem estimate` and `sigmafem demo`: read the data, build
// the ensemble on the chosen back end, run the filter, write the outputs.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <string>

#include "host/common/device_options.h"
#include "host/scenario/scenario.h"

namespace sigmafem::cli {

struct EstimationJob {
  std::string data_dir;
  std::string out_dir;
  std::string backend = "auto";    // or cpu, opencl, vulkan (make_ensemble)
  DeviceOptions device;            // for a device back end
  std::string sigma_points;        // "" = the scenario's filter.sigma_points
  bool progress = true;
  std::ostream* out = nullptr;     // the back end's line ("backend: ..."), before the run
};

// Runs the job; returns the summary written to summary.json. Throws InputError for bad input
// (a scenario without a filter block, data that does not match the scenario, ...). A filter
// that diverges is not an exception: the summary says "complete": false and why.
// Under `mpirun -n R` (R > 1) every rank runs it: each makes its share of the sigma points
// (host/mpi/distributed_ensemble.h), rank 0 runs the filter and writes everything, and the
// other ranks serve their shares and return nothing.
std::optional<nlohmann::ordered_json> run_estimation_job(const Scenario& scenario, const EstimationJob& job);

// A few lines for the terminal: final estimates, errors against the truth, where the files are.
void print_estimation_summary(std::ostream& out, const nlohmann::ordered_json& summary,
                              const std::string& out_dir);

}  // namespace sigmafem::cli
