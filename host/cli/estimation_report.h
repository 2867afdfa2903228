// The outputs of `sigmafem estimate` (docs/FORMATS.md): estimates.csv, summary.json,
// residual.json (the residual diagnostics and their verdict, host/cli/residual_report.h) and
// three PNG plots (estimated stiffness with a +-2 std band against the truth, one line per
// ligament, as the seed paper's Figures 3 and 4; innovation RMS over the steps; NIS and
// standardised innovations over the steps).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "filter/estimation.h"
#include "filter/error_figures.h"
#include "filter/residual_diagnostics.h"
#include "host/data/truth_table.h"

namespace sigmafem::cli {

struct EstimationReport {
  std::string scenario_name;
  std::string data_dir;
  std::string out_dir;
  std::string backend;          // the back end that ran (cpu, opencl, vulkan)
  std::string backend_reason;   // "given", or why --backend auto chose it
  std::string preconditioner;   // CG's: factorised or jacobi
  std::string sigma_points;
  int sigma_count = 0;
  std::vector<std::string> names;             // estimated ligaments
  std::optional<TruthTable> truth;            // when the data folder has truth.csv
  Eigen::MatrixX3d observed_positions;        // m x 3: mean observed position of each point (m),
                                              // the lever arms of the residual's rigid part
  ResidualDiagnosticsOptions residual;        // burn-in, lags, false-alarm rate
  bool outlier_gate = false;                  // whether the run gated outliers
  nlohmann::ordered_json observations;        // summary.json's "observations": their kind and count
  bool surface_cloud = false;                 // the rows are a cloud's points: the residual tests
                                              // judge the step means (step_means)
  double total_seconds = 0.0;
};

// The truth of the estimated ligaments at the estimate's steps (rows x p), or nullopt if
// `truth` lacks a ligament or a step.
std::optional<Eigen::MatrixXd> truth_at_steps(const TruthTable& truth,
                                              const std::vector<std::string>& names,
                                              const std::vector<int>& steps);

// When and how far the adaptive observation noise engaged (filter/adaptive_noise.h), for
// summary.json and residual.json.
nlohmann::ordered_json adaptive_noise_json(const EstimationRun& run);
// The ligaments the run found cut (EstimationRun::cuts), named by `names` (the estimated
// ligaments in parameter order): summary.json's and report.json's `cuts`.
nlohmann::ordered_json cuts_json(const EstimationRun& run, const std::vector<std::string>& names);
// The parameter-change test's firings (filter/parameter_change_test.h): step, window, statistic
// and the jump of each parameter P was opened by (log units).
nlohmann::ordered_json parameter_changes_json(const EstimationRun& run, const std::vector<std::string>& names);

// Writes every output into report.out_dir (atomically, file by file) and returns the
// summary. Plots are skipped with a note in the summary when gnuplot is missing.
nlohmann::ordered_json write_estimation_report(const EstimationReport& report, const EstimationRun& run);

}  // namespace sigmafem::cli
