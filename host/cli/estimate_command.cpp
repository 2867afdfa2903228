// `sigmafem estimate SCENARIO --data DIR --out DIR [--backend cpu|opencl|vulkan] [--device N]
//  [--precision single|double] [--sigma simplex|star]`.
#include <iostream>
#include <memory>

#include "host/cli/backend_options.h"
#include "host/cli/commands.h"
#include "host/cli/option_checks.h"
#include "host/common/physical_limits.h"
#include "host/cli/estimation_job.h"
#include "host/scenario/scenario.h"

namespace sigmafem::cli {

Action add_estimate_command(CLI::App& app) {
  struct Options {
    std::string scenario;
    EstimationJob job;
    BackendChoice backend;
    bool quiet = false;
    double observation_std = 0.0;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "estimate", "Estimate the ligament stiffnesses from observations with the ROUKF and write "
                  "estimates.csv, summary.json, residual.json, stiffness.png, innovation.png and residual.png");
  sub->add_option("scenario", options->scenario, "Scenario JSON file (with a filter block)")->required();
  sub->add_option("--data", options->job.data_dir, "Folder with observations.csv (and truth.csv)")
      ->required();
  sub->add_option("--out", options->job.out_dir, "Output folder (created if missing)")->required();
  add_backend_options(sub, options->backend);
  sub->add_option("--sigma", options->job.sigma_points,
                  "Sigma-point set (default: the scenario's filter.sigma_points)")
      ->check(CLI::IsMember(std::vector<std::string>{"simplex", "star"}));
  sub->add_option("--observation-std", options->observation_std,
                  "Observation noise std the filter assumes, metres (default: the scenario's "
                  "filter.observation_std)")
      ->check(finite_between(0.0, kMaxNoiseStd, true));
  sub->add_flag("--quiet", options->quiet, "No progress line and no summary");
  return [options]() {
    Scenario scenario = load_scenario(options->scenario);
    if (options->observation_std > 0.0 && scenario.filter)
      scenario.filter->observation_std = options->observation_std;
    options->job.progress = !options->quiet;
    options->job.backend = options->backend.backend;
    options->job.device = options->backend.device_options();
    options->job.out = options->quiet ? nullptr : &std::cout;
    const std::optional<nlohmann::ordered_json> summary = run_estimation_job(scenario, options->job);
    if (!summary) return 0;   // an MPI rank other than 0: rank 0 reports
    if (!options->quiet) print_estimation_summary(std::cout, *summary, options->job.out_dir);
    return (*summary)["complete"].get<bool>() ? 0 : 1;
  };
}

}  // namespace sigmafem::cli
