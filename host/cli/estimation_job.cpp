#include "host/cli/estimation_job.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include "filter/estimation.h"
#include "filter/residual_diagnostics.h"
#include "filter/timed_observation.h"
#include "host/cli/estimation_report.h"
#include "host/common/input_error.h"
#include "host/common/progress.h"
#include "host/data/csv_format.h"
#include "host/data/observation_table.h"
#include "host/data/point_cloud_table.h"
#include "host/data/truth_table.h"
#include "host/engine/choose_backend.h"
#include "host/engine/estimation_options.h"
#include "host/engine/make_ensemble.h"
#include "host/engine/surface_cloud_estimation.h"
#include "host/model/effects.h"
#include "host/model/estimated_parameters.h"
#include "host/model/model.h"
#include "host/mpi/distributed_ensemble.h"
#include "host/mpi/ranks.h"

namespace sigmafem::cli {
namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

std::optional<json> run_estimation_job(const Scenario& scenario, const EstimationJob& job) {
  const auto start = std::chrono::steady_clock::now();
  if (!scenario.filter)
    throw InputError("scenario " + scenario.path + ": filter: missing; estimate needs a filter "
                     "block naming the ligaments to estimate and the prior");
  const FilterSpec& spec = *scenario.filter;
  const fs::path data(job.data_dir);
  ObservationTable table =
      read_observations_csv((data / "observations.csv").string(),
                            static_cast<int>(scenario.observations.observed.size()), scenario.time.dt);
  if (table.row_count() < 2)
    throw InputError("observations " + (data / "observations.csv").string() +
                     ": needs at least two rows (the rest state and one step)");
  // A camera offset the scenario declares: the model's observations are the positions plus
  // the offset, i.e. the positions are the data minus the offset.
  const Eigen::Vector3d offset = camera_offset(scenario.effects);
  for (Eigen::Index c = 0; c + 2 < table.points.cols(); c += 3)
    table.points.middleCols(c, 3).rowwise() -= offset.transpose();
  std::optional<TruthTable> truth;
  truth = read_optional_truth_csv((data / "truth.csv").string(), scenario.truth_names(), table.row_count(), std::cerr);
  Model model = make_model(scenario);
  const EstimatedParameters estimated = estimated_parameters(spec, model);   // splits the springs estimated alone

  EstimationOptions options = estimation_options(scenario);
  const bool outlier_gate = options.roukf.outlier_gate.enabled;   // a cloud's observation takes it over
  if (!job.sigma_points.empty()) options.roukf.sigma_points = parse_sigma_point_set(job.sigma_points);
  const int sigma_count = sigma_point_count(options.roukf.sigma_points, estimated.count());

  const RankInfo& world = ranks();
  if (world.distributed() && scenario.observations.surface_cloud)
    throw InputError("scenario " + scenario.path + ": a surface cloud's estimation runs on one rank, not over " +
                     std::to_string(world.size) + " MPI ranks");
  if (world.size > sigma_count)
    throw InputError(std::to_string(world.size) + " MPI ranks for " + std::to_string(sigma_count) +
                     " sigma points: every rank needs at least one (run with -n " + std::to_string(sigma_count) +
                     " or fewer)");
  const BackendDecision backend = resolve_backend(job.backend, model, sigma_count, estimated);
  if (job.out && world.rank == 0) *job.out << "backend: " << backend.backend << " (" << backend.reason << ")\n" << std::flush;
  // A surface cloud (observations.surface_cloud): the ensemble observes the surface's nodes
  // and each frame's points are observed by their distance to it
  // (host/engine/surface_cloud_estimation.h).
  std::optional<SurfaceCloudEstimation> cloud;
  std::unique_ptr<TimedObservation> tracked;
  DistributedEnsemble* distributed = nullptr;   // over MPI ranks, inside `tracked`
  nlohmann::ordered_json observations = {{"kind", "tracked_points"}, {"points", table.point_count()}};
  if (scenario.observations.surface_cloud) {
    const std::string cloud_path = (data / "pointcloud.csv").string();
    PointCloudTable cloud_table = read_point_cloud_csv(cloud_path);
    for (PointCloudFrame& frame : cloud_table.frames) frame.points.colwise() -= offset;
    cloud = make_surface_cloud_estimation(backend.backend, model, scenario.mesh, estimated, sigma_count,
                                          job.device, cloud_table, scenario.time.dt, table.row_count(), cloud_path,
                                          options.roukf);
    Eigen::Index max_points = 0;
    for (const StepFrames& step : cloud->frames) max_points = std::max(max_points, step.points.cols());
    observations = {{"kind", "surface_cloud"},
                    {"frames", cloud_table.frames.size()},
                    {"points", cloud_table.point_count()},
                    {"max_points_per_step", max_points},
                    {"surface_triangles", cloud->surface_triangles}};
  } else if (!world.distributed()) {
    // Frames at their own times (observations.csv's frame_time) are observed then
    // (filter/timed_observation.h); without the column the decorator changes nothing.
    tracked = std::make_unique<TimedObservation>(
        make_ensemble(backend.backend, model, estimated, scenario.observations.observed, sigma_count, job.device),
        table.frame_shares);
    if (!table.frame_times.empty()) observations["frame_time"] = true;
  } else {
    // Over MPI ranks: every rank makes its share; all learn whether every rank has one. The
    // CPU back end's threads share the machine's cores with the other ranks on it.
    DeviceOptions device = job.device;
    if (device.cpu_threads == 0)
      device.cpu_threads = world.cores_per_rank();
    std::unique_ptr<SimulationEnsemble> local = make_share(sigma_count, [&](int count) {
      return make_ensemble(backend.backend, model, estimated, scenario.observations.observed, count, device);
    });
    if (world.rank != 0) {
      serve_ensemble(*local, sigma_count);
      return std::nullopt;
    }
    auto ensemble = std::make_unique<DistributedEnsemble>(std::move(local), sigma_count);
    distributed = ensemble.get();
    tracked = std::make_unique<TimedObservation>(std::move(ensemble), table.frame_shares);
    if (!table.frame_times.empty()) observations["frame_time"] = true;
    observations["mpi_ranks"] = world.size;
  }
  fs::create_directories(job.out_dir);   // once the ensemble stands (on rank 0 alone over MPI)
  Progress progress("estimate " + scenario.name + ": step", table.row_count() - 1, job.progress);
  std::optional<EstimationRun> finished;
  try {
    finished = run_estimation(
        cloud ? static_cast<Ensemble&>(*cloud->ensemble) : *tracked, options, table.times, table.so,
        cloud ? cloud->measured : table.points,
        [&](const EstimationStep& step) {
          char detail[160];
          std::snprintf(detail, sizeof detail, "innovation %.3f mm", 1e3 * step.innovation_rms);
          progress.update(step.step, detail);
        },
        [&](Eigen::Index row) {
          if (cloud) cloud->before_step(row);
          if (tracked) tracked->set_row(row);
        });
  } catch (...) {
    if (distributed) distributed->stop_after(std::current_exception());   // every rank ends with it
    throw;
  }
  // A step that failed on any rank ends the run incomplete (run_estimation), on every rank.
  if (distributed) distributed->stop(finished->complete ? 0 : 1, finished->stop_reason);
  progress.finish();
  const EstimationRun& run = *finished;

  EstimationReport report;
  report.scenario_name = scenario.name;
  report.data_dir = job.data_dir;
  report.out_dir = job.out_dir;
  report.backend = backend.backend;
  report.backend_reason = backend.reason;
  report.preconditioner = preconditioner_used(backend.backend, job.device, model);
  report.sigma_points = to_string(options.roukf.sigma_points);
  report.outlier_gate = outlier_gate;
  report.sigma_count = sigma_count;
  report.names = scenario.parameter_names();
  report.truth = truth;
  // The residual diagnostics' lever arms: tracked points only (for a cloud the rows are not
  // the same points from one step to the next, and the report leaves them out).
  if (!cloud) report.observed_positions = mean_observed_positions(table.points);
  report.observations = observations;
  report.surface_cloud = cloud.has_value();
  report.total_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return write_estimation_report(report, run);
}

void print_estimation_summary(std::ostream& out, const json& summary, const std::string& out_dir) {
  char line[256];
  const json& timing = summary["timing"];
  std::snprintf(line, sizeof line, "estimated '%s' over %d filter steps (%s, %s sigma points x%d): %.2f ms per step\n",
                summary["scenario"].get<std::string>().c_str(), summary["filter_steps"].get<int>(),
                summary["backend"].get<std::string>().c_str(),
                summary["sigma_points"].get<std::string>().c_str(), summary["sigma_count"].get<int>(),
                timing["filter_step_mean_ms"].get<double>());
  out << line;
  // For real time: how long the worst steps took (the first apart: it makes the first
  // preconditioner).
  if (summary["filter_steps"].get<int>() > 1) {
    std::snprintf(line, sizeof line, "  steps after the first: 99%% within %.2f ms, the slowest %.2f ms (step %d); the first %.2f ms\n",
                  timing["filter_step_p99_ms"].get<double>(), timing["filter_step_max_after_first_ms"].get<double>(),
                  timing["slowest_step_after_first"].get<int>(), timing["filter_step_first_ms"].get<double>());
    out << line;
  }
  if (!summary["complete"].get<bool>())
    out << "  INCOMPLETE: " << summary["stop_reason"].get<std::string>() << '\n';
  for (const auto& [name, value] : summary["final"].items()) {
    if (value.contains("young_modulus_pa"))
      std::snprintf(line, sizeof line, "  %-12s %10.0f Pa   +- %.0f (1 std)\n", name.c_str(),
                    value["young_modulus_pa"].get<double>(), value["std_pa"].get<double>());
    else
      std::snprintf(line, sizeof line, "  %-12s %10.2f N/m  +- %.2f (1 std)\n", name.c_str(),
                    value["stiffness_n_per_m"].get<double>(), value["std_n_per_m"].get<double>());
    out << line;
  }
  if (summary["errors"].is_object()) {
    for (const auto& [phase, e] : summary["errors"].items()) {
      std::snprintf(line, sizeof line, "  %-11s mean |error| %.2f N/m over its last 20%%, truth inside +-2 std %.0f%%",
                    phase.c_str(), e["mean_abs_error_n_per_m"].get<double>(),
                    100.0 * e["coverage_2std"].get<double>());
      out << line;
      if (e.contains("steps_to_follow"))
        out << ", followed the change in "
            << (e["steps_to_follow"].is_null() ? std::string("(never)")
                                                : std::to_string(e["steps_to_follow"].get<int>()) + " steps");
      out << '\n';
    }
  }
  if (summary.contains("young_modulus_errors")) {
    std::string worst;
    double largest = -1.0;
    for (const auto& [name, e] : summary["young_modulus_errors"].items())
      if (std::abs(e["relative_error"].get<double>()) > largest) {
        largest = std::abs(e["relative_error"].get<double>());
        worst = name;
      }
    std::snprintf(line, sizeof line, "  regions     largest |error| of a Young's modulus %.1f%% (%s) at the last step\n",
                  100.0 * largest, worst.c_str());
    out << line;
  }
  if (!summary["outliers_rejected"].is_null())
    out << "  outliers: " << summary["outliers_rejected"].get<int>()
        << " point-steps left out by the outlier gate\n";
  if (summary["adaptive_noise"]["engaged"].get<bool>())
    out << "  adaptive noise: engaged on " << summary["adaptive_noise"]["steps"].get<int>() << " steps from step "
        << summary["adaptive_noise"]["first_step"].get<int>() << ", noise variance scaled by up to "
        << format_number(summary["adaptive_noise"]["max_scale"].get<double>())
        << " (innovations beyond what the parameters explain: a model error, or a change in the steps "
           "before the detector fired)\n";
  if (summary["catch_up_steps"].get<int>() > 0) {
    // Either test may begin a catch-up: the NIS detector's changes, the parameter-change test's.
    std::vector<int> parameter_changes;
    for (const auto& change : summary["parameter_changes"]) parameter_changes.push_back(change["step"].get<int>());
    out << "  changes detected at steps " << summary["changes_detected_at_steps"].dump()
        << " (parameter changes at " << json(parameter_changes).dump() << "); " << summary["catch_up_steps"].get<int>()
        << " steps of catch-up after them are left out of the residual tests\n";
  }
  for (const auto& cut : summary["cuts"]) {
    std::snprintf(line, sizeof line,
                  "  ligament %s cut at step %d (t = %.2f s): the data show it lost nearly all of the %.4g N/m it "
                  "had before the change; held at zero since (docs/ROUKF.md \"Cut ligaments\")\n",
                  cut["ligament"].get<std::string>().c_str(), cut["step"].get<int>(), cut["time_s"].get<double>(),
                  cut["stiffness_before_n_per_m"].get<double>());
    out << line;
  }
  if (summary["residual"].is_object()) {
    const auto& residual = summary["residual"];
    out << "  residuals: " << residual["verdict"].get<std::string>();
    if (!residual["failed_tests"].empty()) {
      out << " (failed:";
      for (const auto& name : residual["failed_tests"]) out << ' ' << name.get<std::string>();
      out << ')';
    }
    out << '\n';
  }
  const fs::path dir(out_dir);
  out << "  " << (dir / "estimates.csv").string() << "\n  " << (dir / "summary.json").string() << '\n';
  if (summary["residual"].is_object()) out << "  " << summary["residual"]["file"].get<std::string>() << '\n';
  if (summary["plots"].contains("skipped"))
    out << "  plots skipped: " << summary["plots"]["skipped"].get<std::string>() << '\n';
  else
    out << "  " << summary["plots"]["stiffness"].get<std::string>() << "\n  "
        << summary["plots"]["innovation"].get<std::string>() << '\n';
  if (summary["plots"].contains("residual"))
    out << "  " << summary["plots"]["residual"].get<std::string>() << '\n';
}

}  // namespace sigmafem::cli
