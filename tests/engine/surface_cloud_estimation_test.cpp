// The liver estimated from surface point clouds (issue 15, item 2; scenarios/liver_cloud.json:
// 300 points per frame on the anterior third of the surface, the same ligaments and motion as
// liver.json), through make_surface_cloud_estimation as `estimate` builds it, over the 10 s
// before the cut:
//   noise-free, every stiffness within 2% of the truth;
//   at 0.5 mm noise with 5% outliers at 1-2 cm and 10% dropouts, with the outlier gate: the
//   error within 1.5x of the same data without the faults, the truth inside +-2 std on 90%
//   of the scored steps;
//   frames at 30 Hz with 3 ms jitter as good as the same frames on the step grid.
#include "host/engine/surface_cloud_estimation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <iostream>
#include <sstream>
#include <string>

#include "filter/error_figures.h"
#include "filter/estimation.h"
#include "filter/residual_diagnostics.h"
#include "host/data/observation_table.h"
#include "host/data/truth_table.h"
#include "host/generator/generate.h"
#include "host/scenario/scenario.h"
#include "temp_path.h"
#include "tests/filter/scenario_filter_options.h"

namespace sigmafem {
namespace {

struct CloudRun {
  EstimationRun run;
  PhaseErrors phase;            // over the last 20% of the steps (error_figures)
  double relative_error = 0.0;  // the largest over ligaments of mean |estimate - truth| / truth there
  GenerateResult generated;
};

// Generates liver_cloud's first `step_count` steps (no cut) with `noise`, the faults and frame
// times of `generate_options` and estimates them on the CPU back end with the filter told
// `observation_std`.
CloudRun run_liver_cloud(double noise, double observation_std, GenerateOptions generate_options, bool gate,
                         int step_count = 1000) {
  Scenario s = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/liver_cloud.json");
  s.events.clear();
  s.time.steps = step_count;
  s.observations.noise_std = noise;
  const test::TempDir dir("sigmafem_surface_cloud_estimation_test");
  generate_options.out_dir = dir.path();
  generate_options.vtk_every = 0;
  std::ostringstream log;
  CloudRun result;
  result.generated = generate(s, generate_options, log);
  const ObservationTable table = read_observations_csv(dir.file("observations.csv"), 0, s.time.dt);
  const TruthTable truth = read_truth_csv(dir.file("truth.csv"));
  const PointCloudTable cloud = read_point_cloud_csv(dir.file("pointcloud.csv"));

  EstimationOptions options = test::filter_options(s, SigmaPointSet::simplex, observation_std);
  options.roukf.outlier_gate.enabled = gate;
  const int p = static_cast<int>(s.filter->estimate.size());
  SurfaceCloudEstimation estimation =
      make_surface_cloud_estimation("cpu", make_model(s), s.mesh, s.filter->estimate,
                                    sigma_point_count(SigmaPointSet::simplex, p), {}, cloud, s.time.dt,
                                    table.row_count(), dir.file("pointcloud.csv"), options.roukf);
  result.run = run_estimation(*estimation.ensemble, options, table.times, table.so, estimation.measured, {},
                              [&](Eigen::Index row) { estimation.before_step(row); });
  const auto rows = static_cast<Eigen::Index>(result.run.steps.size());
  Eigen::MatrixXd estimate(rows, p), std_dev(rows, p), truth_at(rows, p);
  std::vector<int> steps;
  for (Eigen::Index k = 0; k < rows; ++k) {
    const EstimationStep& step = result.run.steps[static_cast<std::size_t>(k)];
    steps.push_back(step.step);
    estimate.row(k) = step.stiffness.transpose();
    std_dev.row(k) = step.stiffness_std.transpose();
    for (int j = 0; j < p; ++j) truth_at(k, j) = truth.stiffness(step.step, s.filter->estimate[static_cast<std::size_t>(j)]);
  }
  result.phase = error_figures(steps, estimate, std_dev, truth_at).at(0);
  const Eigen::Index scored = rows / 5;
  const Eigen::ArrayXXd relative = ((estimate.bottomRows(scored) - truth_at.bottomRows(scored)).array().abs() /
                                    truth_at.bottomRows(scored).array());
  result.relative_error = relative.colwise().mean().maxCoeff();
  return result;
}

// Measured data's faults (issue 15): 5% of the points 1-2 cm off, 10% missing.
GenerateOptions with_faults() {
  GenerateOptions options;
  options.outliers = 0.05;
  options.dropouts = 0.10;
  return options;
}

// Frames at 30 Hz against the 100 Hz simulation, taken at their own times with 3 ms jitter,
// or at the steps nearest their nominal times.
GenerateOptions at_30_hz(bool own_times) {
  GenerateOptions options;
  options.frame_rate = 30.0;
  options.frame_jitter = own_times ? 0.003 : 0.0;
  options.frames_on_steps = !own_times;
  return options;
}

// On noise-free data the filter is told of a small observation noise (issue 3): 0.1 mm.
TEST(LiverCloudEstimation, NoiseFreeCloudsGiveEveryStiffnessWithinTwoPercent) {
  const CloudRun cloud = run_liver_cloud(0.0, 1e-4, {}, false);
  ASSERT_TRUE(cloud.run.complete) << cloud.run.stop_reason;
  EXPECT_LT(cloud.relative_error, 0.02);
  std::cout << "liver, noise-free clouds: largest mean relative error " << 100.0 * cloud.relative_error
            << "%, mean |error| " << cloud.phase.mean_abs_error << " N/m\n";
}

TEST(LiverCloudEstimation, OutliersAndDropoutsCostLittleWithTheOutlierGate) {
  const CloudRun clean = run_liver_cloud(5e-4, 5e-4, {}, true);
  const CloudRun faulty = run_liver_cloud(5e-4, 5e-4, with_faults(), true);
  ASSERT_TRUE(clean.run.complete && faulty.run.complete) << clean.run.stop_reason << faulty.run.stop_reason;
  EXPECT_LE(faulty.phase.mean_abs_error, 1.5 * clean.phase.mean_abs_error);
  EXPECT_GE(faulty.phase.coverage, 0.9);
  // The clean clouds' residual is consistent (the step means' tests, filter/residual_diagnostics.h).
  const ResidualDiagnostics verdict = diagnose_residuals(step_means(innovation_series(clean.run)), {});
  EXPECT_EQ(verdict.verdict.consistency, Consistency::consistent)
      << "failed: " << ::testing::PrintToString(verdict.verdict.failed());
  std::cout << "liver clouds at 0.5 mm: mean |error| " << clean.phase.mean_abs_error << " N/m without faults (coverage "
            << 100.0 * clean.phase.coverage << "%), " << faulty.phase.mean_abs_error << " N/m with them (coverage "
            << 100.0 * faulty.phase.coverage << "%); outliers generated " << faulty.generated.outliers
            << ", left out " << faulty.run.outliers << "; left out of the clean data " << clean.run.outliers << "\n";
}

// Frames at their own times (issue 15, item 3): 30 Hz with 3 ms jitter are as good as the
// same frames on the step grid, within 10%, because each point is observed on the surface of
// the moment it was taken (filter/point_cloud_observation.h). Noise-free, where a timing
// error shows most: given to the nearest step instead, the error was 2.46 N/m against
// 0.20 on the grid (measured at stop 34).
TEST(LiverCloudEstimation, FramesAtTheirOwnTimesAreAsGoodAsFramesOnTheStepGrid) {
  const CloudRun own_times = run_liver_cloud(0.0, 1e-4, at_30_hz(true), false);
  const CloudRun on_grid = run_liver_cloud(0.0, 1e-4, at_30_hz(false), false);
  ASSERT_TRUE(own_times.run.complete && on_grid.run.complete) << own_times.run.stop_reason << on_grid.run.stop_reason;
  // Since issue 16's small drift both are 10-20 times smaller (stop 37: 0.031 N/m with the
  // jitter, 0.011 on the grid, 0.01% and 0.004% of the truth): a floor of 0.05 N/m, 50 times
  // below the nearest-step timing error this test is there to catch, keeps it from comparing
  // interpolation round-off.
  EXPECT_LE(own_times.phase.mean_abs_error, std::max(1.1 * on_grid.phase.mean_abs_error, 0.05));
  std::cout << "liver clouds at 30 Hz, noise-free: mean |error| " << own_times.phase.mean_abs_error
            << " N/m with 3 ms jitter, " << on_grid.phase.mean_abs_error << " N/m on the step grid\n";
}

// Residual diagnostics on clouds (issue 15, item 4): an undeclared camera offset of 3 mm
// across the view moves the cloud off the model's surface; the step means' tests see it
// (measured at stop 34: nis_mean, nis_above_band, whiteness, whiteness_rows and bias_rows
// failed; the clean data's verdict above is consistent, as on seeds 2 and 3 by hand). Since
// issue 16's small drift the stiffnesses no longer wander, and bias_rows passes: nis_mean,
// nis_above_band, whiteness and whiteness_rows fail (stop 37): the NIS's mean is the test asked.
// And the filter completes: with one row per point it diverged at step 72 (the left ligament
// past 1e9 N/m; 1 mm: step 129), because the adaptive noise, which holds the filter under
// model error, takes its strength from the correlation of each row's unexplained innovation
// from step to step, and the rows were other points at every step. Binned by triangle
// (filter/point_cloud_observation.h) the rows are places on the organ, and the run completes
// (stop 35: 1 mm and 3 mm along x and y and 3 mm along z all complete, with stiffnesses at the
// wrong model's optimum, as on tracked points: 2.7 / 710 / 946 N/m there for 3 mm along x).
TEST(LiverCloudEstimation, AnUndeclaredCameraOffsetMakesTheResidualInconsistentAndTheFilterHolds) {
  GenerateOptions offset;
  offset.inject.push_back({"camera_offset", {0.003, 0.0, 0.0}});
  const CloudRun run = run_liver_cloud(5e-4, 5e-4, offset, true);
  EXPECT_TRUE(run.run.complete) << run.run.stop_reason;
  EXPECT_GT(run.run.noise_scaled_steps, 0) << "the adaptive noise answers the model error";
  const ResidualDiagnostics verdict = diagnose_residuals(step_means(innovation_series(run.run)), {});
  EXPECT_EQ(verdict.verdict.consistency, Consistency::inconsistent);
  const std::vector<std::string> failed = verdict.verdict.failed();
  EXPECT_NE(std::find(failed.begin(), failed.end(), "nis_mean"), failed.end())
      << "the cloud lies off the surface: " << ::testing::PrintToString(failed);
}

}  // namespace
}  // namespace sigmafem
