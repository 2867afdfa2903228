#include "host/cli/estimation_report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <vector>

#include "host/cli/plot.h"
#include "host/cli/residual_report.h"
#include "host/common/atomic_file.h"
#include "host/common/output_set.h"
#include "host/data/csv_format.h"

namespace sigmafem::cli {
namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

std::optional<Eigen::MatrixXd> truth_at_steps(const TruthTable& truth,
                                              const std::vector<std::string>& names,
                                              const std::vector<int>& steps) {
  Eigen::MatrixXd values(static_cast<Eigen::Index>(steps.size()),
                         static_cast<Eigen::Index>(names.size()));
  for (std::size_t j = 0; j < names.size(); ++j) {
    const int column = truth.column(names[j]);
    if (column < 0) return std::nullopt;
    for (std::size_t k = 0; k < steps.size(); ++k) {
      if (steps[k] >= truth.stiffness.rows()) return std::nullopt;
      values(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(j)) =
          truth.stiffness(steps[k], column);
    }
  }
  return values;
}


json adaptive_noise_json(const EstimationRun& run) {
  json j;
  j["engaged"] = run.noise_scaled_steps > 0;
  j["steps"] = run.noise_scaled_steps;
  j["first_step"] = run.noise_scaled_steps > 0 ? json(run.first_noise_scaled_step) : json(nullptr);
  j["max_scale"] = run.max_noise_scale;
  j["detail"] = run.noise_scaled_steps == 0
                    ? "the innovations stayed within what the parameters and the stated noise explain: "
                      "every correction used the nominal observation noise"
                    : "the innovations held more than the parameters and the stated noise explain (a model "
                      "error, or a change in the steps before the detector fired): on " + std::to_string(run.noise_scaled_steps) + " steps the correction used the "
                      "observation noise variance scaled by up to " + format_number(run.max_noise_scale) +
                      " so that the parameters are not driven by it; the residual tests use the nominal noise";
  return j;
}

namespace {

std::string estimates_csv(const EstimationReport& report, const EstimationRun& run) {
  std::ostringstream out;
  out << "# scenario " << report.scenario_name << ", data " << report.data_dir << ", backend "
      << report.backend << ", " << report.sigma_points << " sigma points (" << report.sigma_count
      << ")\n";
  if (!run.complete) out << "# incomplete: " << run.stop_reason << '\n';
  out << "step,time";
  for (const std::string& name : report.names) out << ',' << name << ',' << name << "_std";
  out << ",innovation_rms,normalised_innovation,change_detected,noise_scale,catching_up\n";
  for (const EstimationStep& step : run.steps) {
    out << step.step << ',' << format_number(step.time);
    for (Eigen::Index j = 0; j < step.stiffness.size(); ++j)
      out << ',' << format_number(step.stiffness[j]) << ',' << format_number(step.stiffness_std[j]);
    out << ',' << (std::isnan(step.innovation_rms) ? "" : format_number(step.innovation_rms)) << ','
        << format_number(step.normalised_innovation) << ',' << (step.change_detected ? 1 : 0) << ','
        << format_number(step.noise_scale) << ',' << (step.catching_up ? 1 : 0) << '\n';
  }
  return out.str();
}

void plot_stiffness(const EstimationReport& report, const EstimationRun& run,
                    const std::optional<Eigen::MatrixXd>& truth, const std::string& png) {
  PlotData data;
  data.columns = {"time"};
  for (const std::string& name : report.names) {
    data.columns.push_back(name);
    data.columns.push_back(name + "_low");
    data.columns.push_back(name + "_high");
    data.columns.push_back(name + "_truth");
  }
  for (std::size_t k = 0; k < run.steps.size(); ++k) {
    const EstimationStep& step = run.steps[k];
    std::vector<double> row = {step.time};
    for (Eigen::Index j = 0; j < step.stiffness.size(); ++j) {
      row.push_back(step.stiffness[j]);
      row.push_back(std::max(0.0, step.stiffness[j] - 2.0 * step.stiffness_std[j]));
      row.push_back(step.stiffness[j] + 2.0 * step.stiffness_std[j]);
      row.push_back(truth ? (*truth)(static_cast<Eigen::Index>(k), j) : NAN);
    }
    data.rows.push_back(row);
  }
  const bool moduli = std::any_of(report.names.begin(), report.names.end(), is_young_modulus_parameter_name);
  std::ostringstream script;
  script << "set output $output\nset title 'Estimated " << (moduli ? "parameters" : "ligament stiffness") << " ("
         << report.scenario_name << ", " << report.sigma_points << " sigma points): median with +-2 std band"
         << (truth ? ", truth dashed" : "") << "'\n"
         << "set xlabel 'time (s)'\nset ylabel '" << (moduli ? "stiffness (N/m), Young''s modulus E:* (Pa)" : "stiffness (N/m)")
         << "'\nset grid\nset key outside right\n"
         << "set datafile missing 'nan'\n";
  // With a truth, the first seconds' wide prior would squash the rest of the plot: show up
  // to 2.5 times the largest true stiffness (the estimates start at most 2x off here).
  if (truth)
    script << "set yrange [0:" << format_number(2.5 * truth->maxCoeff()) << "]\n";
  else
    script << "set yrange [0:*]\n";
  script
         << "colors = '#1f77b4 #d62728 #2ca02c #9467bd #ff7f0e #8c564b #e377c2 #7f7f7f'\n"
         << "plot ";
  for (std::size_t j = 0; j < report.names.size(); ++j) {
    const int base = 2 + 4 * static_cast<int>(j);
    const std::string color = "word(colors, " + std::to_string(j % 8 + 1) + ")";
    script << (j ? ", " : "") << "$data using 1:" << base + 1 << ':' << base + 2
           << " with filledcurves fs transparent solid 0.2 noborder lc rgb " << color
           << " notitle, $data using 1:" << base << " with lines lw 2 lc rgb " << color
           << " title '" << report.names[j] << "'";
    if (truth)
      script << ", $data using 1:" << base + 3 << " with lines dt 2 lw 1.5 lc rgb " << color
             << " title '" << report.names[j] << " truth'";
  }
  script << '\n';
  render_plot(data, script.str(), png);
}

void plot_innovation(const EstimationReport& report, const EstimationRun& run, const std::string& png) {
  PlotData data;
  data.columns = {"time", "innovation_rms_mm", "change"};
  for (const EstimationStep& step : run.steps)
    data.rows.push_back({step.time, 1e3 * step.innovation_rms, step.change_detected ? 1e3 * step.innovation_rms : NAN});
  std::ostringstream script;
  // A cloud's innovation is each point's signed distance from the model's surface.
  const char* what = report.surface_cloud ? "signed distance of the cloud from the surface" : "observed - predicted position";
  script << "set output $output\nset title 'Innovation RMS (" << what << "), "
         << report.scenario_name << "'\nset xlabel 'time (s)'\nset ylabel 'innovation RMS (mm)'\n"
         << "set logscale y\nset grid\nset datafile missing 'nan'\n"
         << "plot $data using 1:2 with lines lw 2 lc rgb '#1f77b4' title 'innovation RMS', "
         << "$data using 1:3 with points pt 7 ps 1.5 lc rgb '#d62728' title 'change detected'\n";
  render_plot(data, script.str(), png);
}

json phase_json(const PhaseErrors& phase, const std::vector<std::string>& names) {
  json j = {{"first_step", phase.first_step},
            {"last_step", phase.last_step},
            {"mean_abs_error_n_per_m", phase.mean_abs_error},
            {"coverage_2std", phase.coverage}};
  json final_error = json::object();
  for (std::size_t k = 0; k < names.size(); ++k) final_error[names[k]] = phase.final_error[k];
  j["final_abs_error_n_per_m"] = final_error;
  if (phase.name != "before_cut" && phase.name != "phase_0")
    j["steps_to_follow"] = phase.steps_to_follow >= 0 ? json(phase.steps_to_follow) : json(nullptr);
  return j;
}

}  // namespace

nlohmann::ordered_json cuts_json(const EstimationRun& run, const std::vector<std::string>& names) {
  json cuts = json::array();
  for (const LigamentCut& cut : run.cuts)
    cuts.push_back({{"ligament", names[static_cast<std::size_t>(cut.parameter)]},
                    {"step", cut.step},
                    {"time_s", cut.time},
                    {"stiffness_before_n_per_m", cut.stiffness_before},
                    {"upper_bound_n_per_m", cut.upper_bound}});
  return cuts;
}

nlohmann::ordered_json parameter_changes_json(const EstimationRun& run, const std::vector<std::string>& names) {
  json changes = json::array();
  for (const auto& change : run.parameter_changes) {
    json jump = json::object();
    for (std::size_t j = 0; j < names.size() && static_cast<Eigen::Index>(j) < change.jump.size(); ++j)
      if (change.jump[static_cast<Eigen::Index>(j)] != 0.0) jump[names[j]] = change.jump[static_cast<Eigen::Index>(j)];
    changes.push_back({{"step", change.step},
                       {"window_steps", change.window},
                       {"statistic", change.statistic},
                       {"threshold", change.threshold},
                       {"follow_up", change.follow_up},
                       {"opened_log_jump", jump}});
  }
  return changes;
}

nlohmann::ordered_json write_estimation_report(const EstimationReport& report, const EstimationRun& run) {
  // summary.json, what a reader opens first, is the set's marker: published last.
  OutputSet output(report.out_dir,
                   {"estimates.csv", "summary.json", "residual.json", "stiffness.png", "innovation.png", "residual.png"},
                   "summary.json");
  write_file_atomically(output.staged("estimates.csv"), estimates_csv(report, run));

  std::vector<int> steps;
  for (const EstimationStep& step : run.steps) steps.push_back(step.step);
  std::optional<Eigen::MatrixXd> truth;
  if (report.truth) truth = truth_at_steps(*report.truth, report.names, steps);

  json summary;
  summary["scenario"] = report.scenario_name;
  summary["data"] = report.data_dir;
  summary["backend"] = report.backend;
  summary["backend_reason"] = report.backend_reason;
  summary["preconditioner"] = report.preconditioner;
  summary["sigma_points"] = report.sigma_points;
  summary["sigma_count"] = report.sigma_count;
  summary["complete"] = run.complete;
  summary["stop_reason"] = run.complete ? json(nullptr) : json(run.stop_reason);
  summary["filter_steps"] = run.steps.size();
  summary["observations"] = report.observations;
  json final_estimates = json::object();
  double max_seconds = 0.0, sum_seconds = 0.0;
  int max_cg = 0, unconverged = 0, factorisations = 0;
  // A real-time user's figures: the first step apart (it makes the first preconditioner), the
  // slowest of the others and where, and the time 99% of them keep within.
  double first_seconds = 0.0, slowest_seconds = 0.0;
  int slowest_step = 0;
  std::vector<double> seconds;   // of the steps after the first
  json changes = json::array();
  for (const EstimationStep& step : run.steps) {
    if (&step == &run.steps.front()) {
      first_seconds = step.seconds;
    } else {
      seconds.push_back(step.seconds);
      if (step.seconds > slowest_seconds) {
        slowest_seconds = step.seconds;
        slowest_step = step.step;
      }
    }
    max_seconds = std::max(max_seconds, step.seconds);
    sum_seconds += step.seconds;
    max_cg = std::max(max_cg, step.max_cg_iterations);
    unconverged += step.unconverged_sigma_points;
    factorisations += step.factorisations;
    if (step.change_detected) changes.push_back(step.step);
  }
  if (!run.steps.empty()) {
    const EstimationStep& last = run.steps.back();
    for (std::size_t j = 0; j < report.names.size(); ++j) {
      const auto jj = static_cast<Eigen::Index>(j);
      const bool modulus = is_young_modulus_parameter_name(report.names[j]);
      final_estimates[report.names[j]] = {{modulus ? "young_modulus_pa" : "stiffness_n_per_m", last.stiffness[jj]},
                                          {modulus ? "std_pa" : "std_n_per_m", last.stiffness_std[jj]},
                                          {"log_std", last.log_std[jj]}};
    }
  }
  summary["final"] = final_estimates;
  const double steps_count = std::max<double>(1.0, static_cast<double>(run.steps.size()));
  double p99_seconds = 0.0;
  if (!seconds.empty()) {
    const std::size_t at = std::min(seconds.size() - 1, static_cast<std::size_t>(0.99 * static_cast<double>(seconds.size())));
    std::nth_element(seconds.begin(), seconds.begin() + static_cast<std::ptrdiff_t>(at), seconds.end());
    p99_seconds = seconds[at];
  }
  summary["timing"] = {{"filter_step_mean_ms", 1e3 * sum_seconds / steps_count},
                       {"filter_step_max_ms", 1e3 * max_seconds},
                       {"filter_step_first_ms", 1e3 * first_seconds},
                       {"filter_step_max_after_first_ms", 1e3 * slowest_seconds},
                       {"slowest_step_after_first", slowest_step},
                       {"filter_step_p99_ms", 1e3 * p99_seconds},
                       {"total_s", report.total_seconds}};
  summary["cg"] = {{"max_iterations", max_cg}, {"unconverged_sigma_steps", unconverged},
                   {"factorisations", factorisations}};
  summary["changes_detected_at_steps"] = changes;
  summary["catch_up_steps"] = run.catch_up_steps;
  summary["parameter_changes"] = parameter_changes_json(run, report.names);
  summary["cuts"] = cuts_json(run, report.names);
  summary["adaptive_noise"] = adaptive_noise_json(run);
  // null when the gate is off (scenario filter.outlier_gate), else the point-steps it left out.
  summary["outliers_rejected"] = report.outlier_gate ? json(run.outliers) : json(nullptr);
  if (truth) {
    Eigen::MatrixXd estimate(static_cast<Eigen::Index>(run.steps.size()),
                             static_cast<Eigen::Index>(report.names.size()));
    Eigen::MatrixXd std_dev(estimate.rows(), estimate.cols());
    for (std::size_t k = 0; k < run.steps.size(); ++k) {
      estimate.row(static_cast<Eigen::Index>(k)) = run.steps[k].stiffness.transpose();
      std_dev.row(static_cast<Eigen::Index>(k)) = run.steps[k].stiffness_std.transpose();
    }
    // The ligaments' figures are in N/m; the regions' moduli, after them (Scenario::
    // parameter_names), get their relative errors at the last step instead.
    const auto ligaments = static_cast<Eigen::Index>(
        std::find_if(report.names.begin(), report.names.end(), is_young_modulus_parameter_name) - report.names.begin());
    json errors = json::object();
    if (ligaments > 0) {
      const std::vector<std::string> ligament_names(report.names.begin(), report.names.begin() + ligaments);
      for (const PhaseErrors& phase : error_figures(steps, estimate.leftCols(ligaments), std_dev.leftCols(ligaments),
                                                    truth->leftCols(ligaments)))
        errors[phase.name] = phase_json(phase, ligament_names);
    }
    summary["errors"] = errors;
    if (ligaments < estimate.cols()) {
      json moduli = json::object();
      const Eigen::Index last = estimate.rows() - 1;
      for (Eigen::Index j = ligaments; j < estimate.cols(); ++j)
        moduli[report.names[static_cast<std::size_t>(j)]] = {
            {"estimate_pa", estimate(last, j)},
            {"truth_pa", (*truth)(last, j)},
            {"relative_error", (estimate(last, j) - (*truth)(last, j)) / (*truth)(last, j)}};
      summary["young_modulus_errors"] = moduli;
    }
  } else {
    summary["errors"] = nullptr;
  }

  // Residual diagnostics (issue 6): does the model explain the data?
  const InnovationSeries series = report.surface_cloud ? step_means(innovation_series(run)) : innovation_series(run);
  std::optional<ResidualDiagnostics> residual;
  if (!run.steps.empty() &&
      (report.surface_cloud || 3 * report.observed_positions.rows() == series.innovation.cols())) {
    residual = diagnose_residuals(series, report.surface_cloud ? Eigen::MatrixX3d() : report.observed_positions,
                                  report.residual);
    json residual_file = residual_json(*residual, report.residual);
    residual_file["adaptive_noise"] = summary["adaptive_noise"];
    write_file_atomically(output.staged("residual.json"), residual_file.dump(2) + "\n");
    summary["residual"] = {{"verdict", to_string(residual->verdict.consistency)},
                           {"failed_tests", residual->verdict.failed()},
                           {"file", output.final_path("residual.json")}};
  } else {
    summary["residual"] = nullptr;
  }

  json plots = json::object();
  if (run.steps.empty()) {
    plots["skipped"] = "no filter step";
  } else if (!gnuplot_available()) {
    plots["skipped"] = "gnuplot (with the pngcairo terminal) is not installed: apt-get install gnuplot-nox";
  } else {
    plot_stiffness(report, run, truth, output.staged("stiffness.png"));
    plot_innovation(report, run, output.staged("innovation.png"));
    plots["stiffness"] = output.final_path("stiffness.png");
    plots["innovation"] = output.final_path("innovation.png");
    if (residual) {
      plot_residuals(*residual, series, report.scenario_name, output.staged("residual.png"));
      plots["residual"] = output.final_path("residual.png");
    }
  }
  summary["plots"] = plots;
  write_file_atomically(output.staged("summary.json"), summary.dump(2) + "\n");
  output.publish();
  return summary;
}

}  // namespace sigmafem::cli
