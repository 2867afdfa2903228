// The whole estimation on the paper's box and on the liver (issue 3): from noise-free data and
// a prior 2x off the truth, the ROUKF with the CPU ensemble converges to the truth, follows
// the cut, and keeps the uncut ligaments' estimates sane through it; at 0.5 mm noise the truth
// lies inside the stated intervals; with no cut the change detector stays silent; missing
// observations are handled.
#include <gtest/gtest.h>

#include <Eigen/LU>

#include <algorithm>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <tuple>

#include "temp_path.h"
#include "generated_data.h"
#include "tests/filter/scenario_filter_options.h"
#include "filter/error_figures.h"
#include "filter/estimation.h"
#include "host/data/observation_table.h"
#include "host/data/truth_table.h"
#include "host/ensemble/cpu_ensemble.h"
#include "host/generator/generate.h"
#include "host/model/model.h"
#include "host/scenario/scenario.h"

namespace sigmafem {
namespace {
namespace fs = std::filesystem;

// Issue 3's figures for noise-free box data.
constexpr double kBeforeCutError = 1.0;   // N/m, mean |error| over the last 20% before the cut
constexpr double kAfterCutError = 3.0;    // N/m, the same after the cut
constexpr int kStepsToFollow = 150;       // filter steps from the cut until within 5% / 5 N/m
// On noise-free data the filter is told of a small observation noise (issue 3): 0.1 mm, a
// fifth of the scenario's 0.5 mm.
constexpr double kNoiseFreeObservationStd = 1e-4;

struct ExperimentData {
  Scenario scenario;
  ObservationTable observations;
  TruthTable truth;
  GenerateResult generated;
};

// Measured data's faults in the data of OutliersAndDropouts and LongGaps (issue 15): 5% of
// the point-steps 1-2 cm off, 10% missing.
constexpr double kOutliers = 0.05;
constexpr double kDropouts = 0.10;

using test::filter_options;

// Generates a shipped scenario's data once per configuration (noise, with or without the cut,
// with or without the faults above, the noise the same with and without them; `steps` > 0
// shortens the run).
const ExperimentData& experiment_data(const std::string& name, bool noise_free, bool with_cut,
                                      bool with_faults = false, int steps = 0, double gap_steps = 1.0) {
  static std::map<std::tuple<std::string, bool, bool, bool, int, double>, std::unique_ptr<ExperimentData>> cache;
  auto& slot = cache[{name, noise_free, with_cut, with_faults, steps, gap_steps}];
  if (!slot) {
    slot = std::make_unique<ExperimentData>();
    slot->scenario = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/" + name + ".json");
    if (noise_free) slot->scenario.observations.noise_std = 0.0;
    if (!with_cut) slot->scenario.events.clear();
    if (steps > 0) slot->scenario.time.steps = steps;
    const fs::path dir = test::unique_temp_path("sigmafem_estimation_box_test");
    GenerateOptions options;
    options.out_dir = dir.string();
    options.vtk_every = 0;
    if (with_faults) {
      options.outliers = kOutliers;
      options.dropouts = kDropouts;
      options.gap_steps = gap_steps;
    }
    std::ostringstream log;
    slot->generated = generate(slot->scenario, options, log);
    slot->observations = read_observations_csv((dir / "observations.csv").string(),
                                               static_cast<int>(slot->scenario.observations.nodes.size()),
                                               slot->scenario.time.dt);
    slot->truth = read_truth_csv((dir / "truth.csv").string());
    fs::remove_all(dir);
  }
  return *slot;
}

struct ExperimentRun {
  EstimationRun run;
  std::vector<int> steps;
  Eigen::MatrixXd estimate, std_dev, truth;   // rows = filter steps, columns = estimated
};

ExperimentRun run_experiment(const ExperimentData& data, SigmaPointSet set, double observation_std,
               const Eigen::MatrixXd& points, bool outlier_gate = false) {
  const Scenario& s = data.scenario;
  EstimationOptions options = filter_options(s, set, observation_std);
  options.roukf.outlier_gate.enabled = outlier_gate;
  const int p = static_cast<int>(s.filter->estimate.size());
  CpuEnsemble ensemble(make_model(s), s.filter->estimate, s.observations.nodes,
                       sigma_point_count(set, p));
  ExperimentRun box;
  box.run = run_estimation(ensemble, options, data.observations.times, data.observations.so,
                           points, {});
  const Eigen::Index rows = static_cast<Eigen::Index>(box.run.steps.size());
  box.estimate.resize(rows, p);
  box.std_dev.resize(rows, p);
  box.truth.resize(rows, p);
  for (Eigen::Index k = 0; k < rows; ++k) {
    const EstimationStep& step = box.run.steps[static_cast<std::size_t>(k)];
    box.steps.push_back(step.step);
    box.estimate.row(k) = step.stiffness.transpose();
    box.std_dev.row(k) = step.stiffness_std.transpose();
    for (int j = 0; j < p; ++j)
      box.truth(k, j) = data.truth.stiffness(step.step, s.filter->estimate[static_cast<std::size_t>(j)]);
  }
  return box;
}

class BoxEstimationTest : public ::testing::TestWithParam<SigmaPointSet> {};

TEST_P(BoxEstimationTest, ConvergesFromTwiceTheTruthAndFollowsTheCut) {
  const ExperimentData& data = experiment_data("box", true, true);
  const ExperimentRun box = run_experiment(data, GetParam(), kNoiseFreeObservationStd, data.observations.points);
  ASSERT_TRUE(box.run.complete) << box.run.stop_reason;
  const std::vector<PhaseErrors> phases = error_figures(box.steps, box.estimate, box.std_dev, box.truth);
  ASSERT_EQ(phases.size(), 2u) << "one cut: two phases";
  EXPECT_LT(phases[0].mean_abs_error, kBeforeCutError) << to_string(GetParam()) << ": before the cut";
  EXPECT_LT(phases[1].mean_abs_error, kAfterCutError) << to_string(GetParam()) << ": after the cut";
  EXPECT_GE(phases[1].steps_to_follow, 0) << "the estimates must settle after the cut";
  EXPECT_LE(phases[1].steps_to_follow, kStepsToFollow) << to_string(GetParam());
  // Through the cut, no uncut ligament's estimate leaves 0.1x..10x of its truth.
  const int middle = data.scenario.ligament_index("middle");
  for (Eigen::Index k = phases[1].first_step - 1; k < box.estimate.rows(); ++k) {
    for (Eigen::Index j = 0; j < box.estimate.cols(); ++j) {
      if (data.scenario.filter->estimate[static_cast<std::size_t>(j)] == middle) continue;
      const double ratio = box.estimate(k, j) / box.truth(k, j);
      ASSERT_TRUE(ratio > 0.1 && ratio < 10.0)
          << "uncut ligament " << j << " at step " << box.steps[static_cast<std::size_t>(k)]
          << ": estimate " << box.estimate(k, j) << ", truth " << box.truth(k, j);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(BothSets, BoxEstimationTest,
                         ::testing::Values(SigmaPointSet::simplex, SigmaPointSet::star),
                         [](const auto& param_info) { return std::string(to_string(param_info.param)); });

TEST(BoxEstimation, ChangeDetectorStaysSilentWithoutACut) {
  // The shipped noise (0.5 mm) and the filter told the same: a model that is right.
  const ExperimentData& data = experiment_data("box", false, false);
  const ExperimentRun box = run_experiment(data, SigmaPointSet::simplex, data.scenario.filter->observation_std,
                             data.observations.points);
  ASSERT_TRUE(box.run.complete) << box.run.stop_reason;
  EXPECT_EQ(box.run.changes_detected, 0) << "a false alarm over " << box.run.steps.size() << " steps";
  EXPECT_TRUE(box.run.cuts.empty()) << "no change, no cut";
}

TEST(BoxEstimation, ChangeDetectorFiresOnTheCutWithASmallDrift) {
  // With a drift of 0.02 the filter follows a cut slowly, so the innovations after it stay
  // large for a while: the detector must fire soon after the cut (and not before it), and
  // widen the covariance so that the estimates still follow within the goal.
  const ExperimentData& data = experiment_data("box", true, true);
  const Scenario& s = data.scenario;
  EstimationOptions options = filter_options(s, SigmaPointSet::simplex, kNoiseFreeObservationStd);
  options.roukf.parameter_drift_log_std = 0.02;
  // The NIS detector's own part: with the parameter-change test on, it opens P first and the
  // NIS never jumps (EstimationHistory runs both).
  options.change_test.enabled = false;
  const int p = static_cast<int>(s.filter->estimate.size());
  CpuEnsemble ensemble(make_model(s), s.filter->estimate, s.observations.nodes, p + 1);
  const EstimationRun run = run_estimation(ensemble, options, data.observations.times,
                                           data.observations.so, data.observations.points, {});
  ASSERT_TRUE(run.complete) << run.stop_reason;
  const int cut_step = static_cast<int>(std::lround(s.events[0].time / s.time.dt));
  std::vector<int> fired;
  for (const EstimationStep& step : run.steps)
    if (step.change_detected) fired.push_back(step.step);
  ASSERT_FALSE(fired.empty()) << "the cut must be detected";
  EXPECT_GE(fired.front(), cut_step) << "fired before the cut";
  EXPECT_LE(fired.front(), cut_step + 50) << "fired late";

  // The catch-up (EstimationStep::catching_up): one block from the first step of the window
  // that fired, through at least the hold-off, at most max_catch_up steps after the firing;
  // nothing is marked before it, and the run counts exactly the marked steps.
  int first = -1, last = -1, marked = 0;
  for (const EstimationStep& step : run.steps)
    if (step.catching_up) {
      if (first < 0) first = step.step;
      last = step.step;
      ++marked;
    }
  EXPECT_EQ(marked, run.catch_up_steps);
  EXPECT_EQ(first, fired.front() - options.detector.window + 1);
  EXPECT_GE(last, fired.front() + options.detector.hold_off);
  EXPECT_LE(last, fired.back() + options.detector.max_catch_up);
  EXPECT_LT(marked, static_cast<int>(run.steps.size()) / 4) << "the catch-up ends";

  // The cut rule (filter/ligament_cut.h): the middle ligament, and only it, is found cut after
  // the firing, and its stiffness stays next to zero from then on (truth 0.01 N/m).
  const auto& estimated = s.filter->estimate;
  const int middle = static_cast<int>(std::find(estimated.begin(), estimated.end(), s.ligament_index("middle")) -
                                      estimated.begin());
  ASSERT_EQ(run.cuts.size(), 1u) << "one ligament cut";
  EXPECT_EQ(run.cuts[0].parameter, middle);
  EXPECT_GE(run.cuts[0].step, fired.front());
  EXPECT_NEAR(run.cuts[0].stiffness_before, 300.0, 15.0) << "the estimate before the cut";
  for (const EstimationStep& step : run.steps) {
    if (step.step > run.cuts[0].step) {
      ASSERT_LT(step.stiffness[middle], 0.01) << "step " << step.step;
    }
  }
}

TEST(BoxEstimation, HandlesMissingObservations) {
  // A third of the observed coordinates are missing at random steps (an occluded marker):
  // the filter drops those rows and still converges before the cut.
  const ExperimentData& data = experiment_data("box", true, true);
  Eigen::MatrixXd points = data.observations.points;
  std::mt19937 engine(4);
  std::bernoulli_distribution missing(1.0 / 3.0);
  for (Eigen::Index k = 1; k < points.rows(); ++k)
    for (Eigen::Index c = 0; c < points.cols(); c += 3)
      if (missing(engine)) points.block(k, c, 1, 3).setConstant(NAN);
  const ExperimentRun box = run_experiment(data, SigmaPointSet::simplex, kNoiseFreeObservationStd, points);
  ASSERT_TRUE(box.run.complete) << box.run.stop_reason;
  const std::vector<PhaseErrors> phases = error_figures(box.steps, box.estimate, box.std_dev, box.truth);
  EXPECT_LT(phases[0].mean_abs_error, kBeforeCutError);
  int fewer = 0;
  for (const EstimationStep& step : box.run.steps) fewer += step.observed_rows < points.cols();
  EXPECT_GT(fewer, 1000) << "most steps had missing rows";
}

// The liver (issue 3): the paper's errors were about 3 and 12 N/m before and after the cut,
// the cut followed in about three times the box's steps; issue 3 asks for under 1.5 and 6 N/m
// within 400 steps on noise-free data. Measured at stop 32 (CPU back end and its factors,
// simplex): 0.12 and 0.65 N/m, followed in 304 steps (the README's table, with Jacobi CG:
// 0.14 and 1.06 N/m, 314 steps).
constexpr double kLiverBeforeCutError = 1.5;   // N/m
constexpr double kLiverAfterCutError = 6.0;    // N/m
constexpr int kLiverStepsToFollow = 400;

TEST(LiverEstimation, ConvergesFromTwiceTheTruthAndFollowsTheCut) {
  const ExperimentData& data = experiment_data("liver", true, true);
  const ExperimentRun liver = run_experiment(data, SigmaPointSet::simplex, kNoiseFreeObservationStd,
                                             data.observations.points);
  ASSERT_TRUE(liver.run.complete) << liver.run.stop_reason;
  const std::vector<PhaseErrors> phases =
      error_figures(liver.steps, liver.estimate, liver.std_dev, liver.truth);
  ASSERT_EQ(phases.size(), 2u) << "one cut: two phases";
  EXPECT_LT(phases[0].mean_abs_error, kLiverBeforeCutError) << "before the cut";
  EXPECT_LT(phases[1].mean_abs_error, kLiverAfterCutError) << "after the cut";
  EXPECT_GE(phases[1].steps_to_follow, 0) << "the estimates must settle after the cut";
  EXPECT_LE(phases[1].steps_to_follow, kLiverStepsToFollow);
  std::cout << "liver, noise-free: mean |error| " << phases[0].mean_abs_error << " and "
            << phases[1].mean_abs_error << " N/m, the cut followed in " << phases[1].steps_to_follow
            << " steps\n";
}

// At the scenarios' 0.5 mm noise (seed 1), issue 16's goals: the truth inside estimate +- 2
// std for at least 90% of each phase's last 20% of steps; before the cut the mean relative
// error over that tail under 2% (box) and 4% (liver); the cut followed within 300 and 400
// steps; no uncut estimate outside 0.1x-10x of its truth at any step. Measured at stop 37
// (the CLI on the same data, CPU back end): box 1.05%, coverage 100% / 98.5%, followed in 185
// steps; liver 3.72%, 98.0% / 100%, 139 steps (158 with stop 38's follow-up;
// seeds 2-5 in the README's table).
constexpr double kCoverageAtHalfAMillimetre = 0.9;

struct NoisyGoal {
  const char* scenario;
  double before_cut_relative_error;
  int steps_to_follow;
};

class NoisyEstimationTest : public ::testing::TestWithParam<NoisyGoal> {};

TEST_P(NoisyEstimationTest, PreciseBeforeTheCutFastAfterItAndHonestThroughout) {
  const NoisyGoal goal = GetParam();
  const ExperimentData& data = experiment_data(goal.scenario, false, true);
  const ExperimentRun run = run_experiment(data, SigmaPointSet::simplex,
                                           data.scenario.filter->observation_std,
                                           data.observations.points);
  ASSERT_TRUE(run.run.complete) << run.run.stop_reason;
  const std::vector<PhaseErrors> phases = error_figures(run.steps, run.estimate, run.std_dev, run.truth);
  ASSERT_EQ(phases.size(), 2u) << "one cut: two phases";
  for (const PhaseErrors& phase : phases) {
    EXPECT_GE(phase.coverage, kCoverageAtHalfAMillimetre) << goal.scenario << ", " << phase.name;
    std::cout << goal.scenario << ", " << phase.name << ": mean |error| " << phase.mean_abs_error
              << " N/m, coverage " << 100.0 * phase.coverage << "%\n";
  }
  // The relative error before the cut, over the same tail error_figures scores.
  const Eigen::Index cut_row = phases[1].first_step - run.steps.front();
  const Eigen::Index tail = static_cast<Eigen::Index>(std::ceil(0.2 * static_cast<double>(cut_row)));
  const double relative =
      ((run.estimate.middleRows(cut_row - tail, tail) - run.truth.middleRows(cut_row - tail, tail)).cwiseAbs().array() /
       run.truth.middleRows(cut_row - tail, tail).array()).mean();
  EXPECT_LT(relative, goal.before_cut_relative_error) << goal.scenario;
  // The cut begins a catch-up at whichever finds it first, the NIS detector or the
  // parameter-change test (a fresh change, not a follow-up): from the first step of the
  // window that fired; nothing is marked before it. Until stop 39 only the detector began
  // one, and on the liver, seed 2 of issue 13's offset and lag cases, the change test
  // followed the cut before the detector fired: no step was left out, and the steps after
  // the cut failed the explained model's residual test by one step.
  const int detector_window =
      filter_options(data.scenario, SigmaPointSet::simplex, data.scenario.filter->observation_std).detector.window;
  int begins = -1;
  for (const EstimationStep& step : run.run.steps)
    if (step.change_detected) {
      begins = step.step - detector_window + 1;
      break;
    }
  for (const auto& change : run.run.parameter_changes)
    if (!change.follow_up) {
      const int change_begins = change.step - change.window + 1;
      if (begins < 0 || change_begins < begins) begins = change_begins;
      break;
    }
  ASSERT_GE(begins, 0) << goal.scenario << ": the cut was not found";
  int first_marked = -1;
  for (const EstimationStep& step : run.run.steps)
    if (step.catching_up) {
      first_marked = step.step;
      break;
    }
  EXPECT_EQ(first_marked, begins) << goal.scenario;
  EXPECT_LT(run.run.catch_up_steps, static_cast<int>(run.run.steps.size()) / 4) << goal.scenario << ": the catch-up ends";
  EXPECT_GE(phases[1].steps_to_follow, 0) << goal.scenario << ": the cut was not followed";
  EXPECT_LE(phases[1].steps_to_follow, goal.steps_to_follow) << goal.scenario;
  std::cout << goal.scenario << ": " << 100.0 * relative << "% before the cut, followed in "
            << phases[1].steps_to_follow << " steps\n";
  for (Eigen::Index k = 0; k < run.estimate.rows(); ++k)
    for (Eigen::Index j = 0; j < run.estimate.cols(); ++j) {
      if (run.truth(k, j) < 1.0) continue;   // the cut one
      const double ratio = run.estimate(k, j) / run.truth(k, j);
      ASSERT_TRUE(ratio > 0.1 && ratio < 10.0) << goal.scenario << ": ligament " << j << " at step "
                                               << run.steps[static_cast<std::size_t>(k)] << ", ratio " << ratio;
    }
}

INSTANTIATE_TEST_SUITE_P(HalfAMillimetre, NoisyEstimationTest,
                         ::testing::Values(NoisyGoal{"box", 0.02, 300}, NoisyGoal{"liver", 0.04, 400}),
                         [](const ::testing::TestParamInfo<NoisyGoal>& param_info) {
                           return std::string(param_info.param.scenario);
                         });

// How precise can the box be before its cut at all? The Cramer-Rao bound of its data: the
// Fisher information of theta = log k summed over the steps, J = P0^-1 + sum_k G_k^T G_k / r^2,
// with G_k the sensitivity of step k's predicted observations to theta (forward differences of
// noise-free simulations, each stiffness times e^0.01) and r the 0.5 mm noise; no unbiased
// estimator's std is below sqrt(diag J^-1). The filter with no drift must attain it: its stated
// std at the end of the phase equals the bound (measured at stop 38: 2.25, 3.81, 3.77 N/m
// against 2.24, 3.84, 3.74), so that its error on a seed is the data's, not the filter's. Seeds
// 2 and 3 of the noisy box miss issue 16's 2% there by exactly that (README, "Estimation
// results"): 1.3-1.9% std per ligament, 3.0% and 3.3% of error at no drift.
TEST(BoxEstimation, WithoutDriftTheStatedStdIsTheCramerRaoBound) {
  constexpr int kSteps = 750;            // the phase before the cut
  constexpr double kStep = 0.01;         // log-stiffness step of the differences
  constexpr double kTolerance = 0.05;    // relative: the sigma points' spread against a derivative
  const ExperimentData& data = experiment_data("box", true, false, false, kSteps);
  const Scenario& s = data.scenario;
  const double r = s.filter->observation_std;
  const int p = static_cast<int>(s.filter->estimate.size());
  Eigen::MatrixXd information = Eigen::MatrixXd::Identity(p, p) / (s.filter->initial_log_std * s.filter->initial_log_std);
  std::vector<Eigen::MatrixXd> moved;    // observations with parameter j moved by kStep
  for (int j = 0; j < p; ++j) {
    Scenario shifted = s;
    shifted.ligaments[static_cast<std::size_t>(s.filter->estimate[static_cast<std::size_t>(j)])].stiffness *= std::exp(kStep);
    moved.push_back(test::generated_observations(shifted).points);
  }
  const Eigen::MatrixXd& base = data.observations.points;
  for (Eigen::Index k = 1; k < base.rows(); ++k) {
    Eigen::MatrixXd sensitivity(base.cols(), p);
    for (int j = 0; j < p; ++j) sensitivity.col(j) = (moved[static_cast<std::size_t>(j)].row(k) - base.row(k)).transpose() / kStep;
    information += sensitivity.transpose() * sensitivity / (r * r);
  }
  const Eigen::VectorXd bound = information.inverse().diagonal().cwiseSqrt();

  EstimationOptions options = filter_options(s, SigmaPointSet::simplex, r);
  options.roukf.parameter_drift_log_std = 0.0;
  options.change_test.enabled = false;
  options.detector.enabled = false;
  CpuEnsemble ensemble(make_model(s), s.filter->estimate, s.observations.nodes, p + 1);
  const EstimationRun run = run_estimation(ensemble, options, data.observations.times, data.observations.so, base, {});
  ASSERT_TRUE(run.complete) << run.stop_reason;
  const EstimationStep& last = run.steps.back();
  for (int j = 0; j < p; ++j) {
    const double truth = s.ligaments[static_cast<std::size_t>(s.filter->estimate[static_cast<std::size_t>(j)])].stiffness;
    std::cout << "ligament " << j << ": stated std " << last.log_std[j] * truth << " N/m, Cramer-Rao bound "
              << bound[j] * truth << " N/m\n";
    EXPECT_NEAR(last.log_std[j] / bound[j], 1.0, kTolerance) << "ligament " << j;
  }
}

// Measured data's faults (issue 15): the box at 0.5 mm noise, its first 600 steps (before the
// cut), with 5% of the point-steps 1-2 cm off and 10% missing. With the outlier gate (filter/outlier_gate.h) the error stays within 1.5x of that on the same
// data without the faults and the truth inside +-2 std on 90% of the steps; the gate leaves
// out nearly every outlier and none of the clean data; without it the outliers pull the
// estimates away.
TEST(BoxEstimation, OutliersAndDropoutsCostLittleWithTheOutlierGate) {
  constexpr int kSteps = 600;
  const ExperimentData& clean = experiment_data("box", false, false, false, kSteps);
  const ExperimentData& faulty = experiment_data("box", false, false, true, kSteps);
  const double sigma = clean.scenario.filter->observation_std;
  auto phase_of = [](const ExperimentRun& run) {
    return error_figures(run.steps, run.estimate, run.std_dev, run.truth).at(0);
  };
  const ExperimentRun reference = run_experiment(clean, SigmaPointSet::simplex, sigma, clean.observations.points, true);
  const ExperimentRun gated = run_experiment(faulty, SigmaPointSet::simplex, sigma, faulty.observations.points, true);
  const ExperimentRun ungated = run_experiment(faulty, SigmaPointSet::simplex, sigma, faulty.observations.points, false);
  ASSERT_TRUE(reference.run.complete && gated.run.complete) << gated.run.stop_reason;
  const PhaseErrors without_faults = phase_of(reference), with_gate = phase_of(gated);
  EXPECT_LE(with_gate.mean_abs_error, 1.5 * without_faults.mean_abs_error);
  EXPECT_GE(with_gate.coverage, kCoverageAtHalfAMillimetre);
  const double without_gate = ungated.run.complete ? phase_of(ungated).mean_abs_error : NAN;
  std::cout << "mean |error| over the last 20%: " << without_faults.mean_abs_error
            << " N/m without the faults, " << with_gate.mean_abs_error << " N/m with them and the gate (coverage "
            << 100.0 * with_gate.coverage << "%), " << without_gate << " N/m without the gate\n";
  const int generated = faulty.generated.outliers;
  std::cout << "outliers: " << generated << " point-steps generated, " << gated.run.outliers
            << " left out by the gate; " << reference.run.outliers << " left out of the clean data\n";
  EXPECT_GE(gated.run.outliers, 0.9 * generated);
  EXPECT_LE(gated.run.outliers, generated);
  EXPECT_EQ(reference.run.outliers, 0) << "a consistent filter's gate leaves out next to nothing";
  // Without the gate the outliers' pull makes the run's path chaotic: 41.1 N/m in the Release
  // build (GCC -O3), 18.4 N/m in the sanitizer build (clang -O1), against 12.5 with the gate
  // in both; asked: clearly worse than with the gate.
  EXPECT_TRUE(!(without_gate <= 1.2 * with_gate.mean_abs_error))
      << "the outliers did not matter without the gate: the test shows nothing";

}

// Gaps (issue 15, item 3): the liver's first 1000 steps at 0.5 mm noise with its 10% of
// point-steps missing in runs of 50 steps on average (a tracker losing a point for half a
// second; generate --gap-steps) and the 5% outliers, the gate on: the error within 1.5x of
// the clean data's, the truth inside +-2 std on 90% of the steps. Measured at stop 34,
// seed 1: 25.2 against 24.7 N/m; seeds 2 and 3 by hand 25.7 against 29.1, 19.6 against 17.6.
TEST(LiverEstimation, LongGapsCostLittle) {
  constexpr int kSteps = 1000;
  const ExperimentData& clean = experiment_data("liver", false, false, false, kSteps);
  const ExperimentData& gaps = experiment_data("liver", false, false, true, kSteps, 50.0);
  const double sigma = clean.scenario.filter->observation_std;
  const ExperimentRun reference = run_experiment(clean, SigmaPointSet::simplex, sigma, clean.observations.points, true);
  const ExperimentRun gapped = run_experiment(gaps, SigmaPointSet::simplex, sigma, gaps.observations.points, true);
  ASSERT_TRUE(reference.run.complete && gapped.run.complete) << gapped.run.stop_reason;
  const PhaseErrors without = error_figures(reference.steps, reference.estimate, reference.std_dev, reference.truth).at(0);
  const PhaseErrors with = error_figures(gapped.steps, gapped.estimate, gapped.std_dev, gapped.truth).at(0);
  EXPECT_LE(with.mean_abs_error, 1.5 * without.mean_abs_error);
  EXPECT_GE(with.coverage, kCoverageAtHalfAMillimetre);
  std::cout << "gaps of 50 steps on average (" << gaps.generated.dropouts << " point-steps missing): mean |error| "
            << with.mean_abs_error << " N/m against " << without.mean_abs_error << " N/m clean, coverage "
            << 100.0 * with.coverage << "%\n";
}

}  // namespace
}  // namespace sigmafem

namespace sigmafem {
namespace {

TEST(EstimationLoop, ShortBoxRunMovesTowardsTheTruth) {
  // The whole loop (ensemble, ROUKF, detector) over 80 steps: short enough for the sanitizer
  // build, where the 1500-step runs above take over ten minutes each (setup.sh skips them
  // there). From the 2x prior, every estimate must get closer to its truth.
  Scenario scenario = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.json");
  scenario.observations.noise_std = 0.0;
  scenario.time.steps = 80;
  const fs::path dir = test::unique_temp_path("sigmafem_estimation_loop_test");
  GenerateOptions generate_options;
  generate_options.out_dir = dir.string();
  generate_options.vtk_every = 0;
  std::ostringstream log;
  generate(scenario, generate_options, log);
  const ObservationTable data = read_observations_csv(
      (dir / "observations.csv").string(), static_cast<int>(scenario.observations.nodes.size()),
      scenario.time.dt);
  fs::remove_all(dir);
  const EstimationOptions options =
      filter_options(scenario, SigmaPointSet::simplex, kNoiseFreeObservationStd);
  CpuEnsemble ensemble(make_model(scenario), scenario.filter->estimate, scenario.observations.nodes, 4);
  const EstimationRun run = run_estimation(ensemble, options, data.times, data.so, data.points, {});
  ASSERT_TRUE(run.complete) << run.stop_reason;
  ASSERT_EQ(run.steps.size(), 80u);
  for (std::size_t j = 0; j < scenario.filter->estimate.size(); ++j) {
    const double truth = scenario.ligaments[static_cast<std::size_t>(scenario.filter->estimate[j])].stiffness;
    const double prior_error = std::fabs(scenario.filter->initial_stiffness[j] - truth);
    const double final_error = std::fabs(run.steps.back().stiffness[static_cast<Eigen::Index>(j)] - truth);
    // Convergence itself is the long tests' job; after 80 steps each error has fallen by about half.
    EXPECT_LT(final_error, 0.75 * prior_error) << "ligament " << j;
    EXPECT_TRUE(run.steps.back().stiffness_std.allFinite());
  }
}

}  // namespace
}  // namespace sigmafem
