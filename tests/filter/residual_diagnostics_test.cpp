// The residual diagnostics on synthetic innovations whose truth is known (white with the
// right covariance; a bias on one row; AR(1) in time; a covariance the filter understates;
// a rigid translation of every point), then on a real filter run of the box, with and
// without a camera registration error the model does not have.
#include "filter/residual_diagnostics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "temp_path.h"
#include "tests/filter/scenario_filter_options.h"
#include "filter/estimation.h"
#include "host/data/observation_table.h"
#include "host/ensemble/cpu_ensemble.h"
#include "host/generator/gaussian_noise.h"
#include "host/generator/generate.h"
#include "host/model/model.h"
#include "host/scenario/scenario.h"

namespace sigmafem {
namespace {
namespace fs = std::filesystem;

constexpr int kResidualPoints = 12, kRows = 3 * kResidualPoints;
constexpr int kSteps = 500;

// Observed points spread over a 30 x 15 x 15 cm box, like the box scenario's top face and more.
Eigen::MatrixX3d synthetic_points() {
  Eigen::MatrixX3d p(kResidualPoints, 3);
  for (int j = 0; j < kResidualPoints; ++j)
    p.row(j) << 0.3 * ((j * 7) % 12) / 11.0, 0.15 * ((j * 5) % 12) / 11.0, 0.15 * ((j * 3) % 4) / 3.0;
  return p;
}

// Innovations with per-row std s_i (0.25..1 mm) as the filter reports them; the actual
// noise is `scale` times that, AR(1) with coefficient `phi` in time (unit variance kept),
// plus a constant `offset` (3m) the model lacks. NIS from the reported (diagonal) S.
InnovationSeries synthetic_series(std::uint64_t seed, double scale = 1.0, double phi = 0.0,
                                  const Eigen::VectorXd& offset = Eigen::VectorXd::Zero(kRows)) {
  GaussianNoise noise(seed);
  InnovationSeries series;
  series.innovation.resize(kSteps, kRows);
  series.innovation_std.resize(kSteps, kRows);
  series.normalised_innovation.resize(kSteps);
  Eigen::VectorXd e(kRows);
  for (int i = 0; i < kRows; ++i) e[i] = noise.next();
  for (int k = 0; k < kSteps; ++k) {
    series.steps.push_back(k + 1);
    series.times.push_back(0.01 * (k + 1));
    series.observed_rows.push_back(kRows);
    for (int i = 0; i < kRows; ++i) {
      if (k > 0) e[i] = phi * e[i] + std::sqrt(1.0 - phi * phi) * noise.next();
      const double s = 0.25e-3 * (1.0 + (i % 4));
      series.innovation(k, i) = scale * s * e[i] + offset[i];
      series.innovation_std(k, i) = s;
    }
    series.normalised_innovation[k] =
        (series.innovation.row(k).array() / series.innovation_std.row(k).array()).square().sum();
  }
  return series;
}

bool failed(const ResidualDiagnostics& d, const std::string& test) {
  for (const std::string& name : d.verdict.failed())
    if (name == test) return true;
  return false;
}

std::string describe(const ResidualDiagnostics& d) {
  std::ostringstream out;
  out << to_string(d.verdict.consistency) << ':';
  for (const DiagnosticTest& test : d.verdict.tests)
    out << "\n  " << test.name << (test.passed ? " passed: " : " FAILED: ") << test.detail;
  return out.str();
}

TEST(ResidualDiagnostics, WhiteInnovationsWithTheRightCovarianceAreConsistent) {
  // 20 seeds; the verdict's false-alarm rate is at most 1%, so more than one inconsistent
  // verdict in 20 would happen with probability under 2%.
  int inconsistent = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    const ResidualDiagnostics d = diagnose_residuals(synthetic_series(seed), synthetic_points());
    ASSERT_EQ(d.steps_used, kSteps - kSteps / 10) << "the default burn-in is 10%";
    EXPECT_NEAR(d.nis.mean / d.nis.mean_dof, 1.0, 0.03) << "seed " << seed;
    // 450 steps: 11.25 above the band expected, std 3.3; 22.5 (5%) is 3.4 std out.
    EXPECT_GT(d.nis.steps_above, 0) << "seed " << seed;
    EXPECT_LT(d.nis.fraction_above, 0.05) << "seed " << seed;
    EXPECT_NEAR(d.whiteness.effective_rows, kRows, 0.1 * kRows) << "independent rows";
    if (d.verdict.consistency != Consistency::consistent) {
      ++inconsistent;
      ADD_FAILURE() << "seed " << seed << " (one is allowed): " << describe(d);
    }
  }
  EXPECT_LE(inconsistent, 1);
}

// The measurement behind the false-alarm figure in residual_diagnostics.h (4000 runs, about
// 5 s): ./sigmafem_tests --gtest_also_run_disabled_tests --gtest_filter='*FalseAlarmRate*'
TEST(ResidualDiagnostics, DISABLED_FalseAlarmRateOverManySeeds) {
  const int runs = 4000;
  int inconsistent = 0;
  std::map<std::string, int> failures;
  for (std::uint64_t seed = 1001; seed <= 1000 + runs; ++seed) {
    const ResidualDiagnostics d = diagnose_residuals(synthetic_series(seed), synthetic_points());
    inconsistent += d.verdict.consistency != Consistency::consistent;
    for (const std::string& name : d.verdict.failed()) ++failures[name];
  }
  std::cout << inconsistent << " inconsistent verdicts in " << runs << " consistent runs:";
  for (const auto& [name, count] : failures) std::cout << ' ' << name << ' ' << count;
  std::cout << '\n';
  EXPECT_LE(inconsistent, runs / 100) << "above the 1% the options ask for";
}

// step_means: one row per step, the mean of its observed rows and that mean's std as if they
// were independent; the NIS and its dof untouched; diagnose_residuals takes it with no
// positions (no spatial pattern, no rigid_bias test).
TEST(ResidualDiagnostics, StepMeansReduceACloudToOneRowPerStep) {
  InnovationSeries series;
  series.steps = {1, 2};
  series.times = {0.01, 0.02};
  series.innovation.resize(2, 3);
  series.innovation << 1.0, 2.0, NAN, 4.0, NAN, NAN;
  series.innovation_std.resize(2, 3);
  series.innovation_std << 3.0, 4.0, NAN, 2.0, NAN, NAN;
  series.normalised_innovation = Eigen::Vector2d(5.0, 6.0);
  series.observed_rows = {2, 1};
  const InnovationSeries means = step_means(series);
  ASSERT_EQ(means.innovation.cols(), 1);
  EXPECT_EQ(means.innovation(0, 0), 1.5);
  EXPECT_EQ(means.innovation_std(0, 0), 2.5) << "sqrt(9 + 16) / 2";
  EXPECT_EQ(means.innovation(1, 0), 4.0);
  EXPECT_EQ(means.innovation_std(1, 0), 2.0);
  EXPECT_EQ(means.normalised_innovation, series.normalised_innovation);
  EXPECT_EQ(means.observed_rows, series.observed_rows);

  const ResidualDiagnostics d = diagnose_residuals(step_means(synthetic_series(3)), Eigen::MatrixX3d());
  EXPECT_EQ(d.verdict.consistency, Consistency::consistent) << describe(d);
  for (const DiagnosticTest& test : d.verdict.tests) EXPECT_NE(test.name, "rigid_bias");
}

TEST(ResidualDiagnostics, ABiasOnOneRowIsFlagged) {
  Eigen::VectorXd offset = Eigen::VectorXd::Zero(kRows);
  const int row = 3 * 5 + 1;                       // point 5, axis y
  offset[row] = 0.25 * 0.25e-3 * (1 + row % 4);    // a quarter of that row's std
  const ResidualDiagnostics d = diagnose_residuals(synthetic_series(3, 1.0, 0.0, offset), synthetic_points());
  EXPECT_EQ(d.verdict.consistency, Consistency::inconsistent) << describe(d);
  EXPECT_TRUE(failed(d, "bias_rows")) << describe(d);
  ASSERT_EQ(d.bias.flagged_rows, std::vector<int>{row}) << describe(d);
  EXPECT_NEAR(d.bias.mean[row], offset[row], 3.0 * d.bias.standard_error[row]);
}

TEST(ResidualDiagnostics, CorrelatedInnovationsFailWhiteness) {
  const ResidualDiagnostics d = diagnose_residuals(synthetic_series(4, 1.0, 0.3), synthetic_points());
  EXPECT_EQ(d.verdict.consistency, Consistency::inconsistent) << describe(d);
  EXPECT_TRUE(failed(d, "whiteness")) << describe(d);
  EXPECT_NEAR(d.whiteness.autocorrelation[0], 0.3, 0.05) << "lag 1 of an AR(1) with phi = 0.3";
  EXPECT_NEAR(d.whiteness.autocorrelation[1], 0.09, 0.05) << "lag 2: phi^2";
  EXPECT_FALSE(failed(d, "nis_mean")) << "the size of the innovations is right: " << describe(d);
}

TEST(ResidualDiagnostics, AnUnderstatedCovarianceFailsTheNisTest) {
  // The actual noise is 1.2x what the filter believes (a 44% larger variance).
  const ResidualDiagnostics d = diagnose_residuals(synthetic_series(5, 1.2), synthetic_points());
  EXPECT_EQ(d.verdict.consistency, Consistency::inconsistent) << describe(d);
  EXPECT_TRUE(failed(d, "nis_mean")) << describe(d);
  EXPECT_NEAR(d.nis.mean / d.nis.mean_dof, 1.44, 0.05);
  EXPECT_FALSE(failed(d, "whiteness")) << describe(d);
  EXPECT_FALSE(failed(d, "bias_rows")) << describe(d);
  // And an overstated one (0.8x) fails it from below.
  const ResidualDiagnostics low = diagnose_residuals(synthetic_series(6, 0.8), synthetic_points());
  EXPECT_TRUE(failed(low, "nis_mean")) << describe(low);
  EXPECT_LT(low.nis.mean, low.nis.band_low);
}

// Every step's innovations scaled by `scale(k)` (the NIS by its square).
InnovationSeries rescaled(InnovationSeries series, const std::function<double(int)>& scale) {
  for (int k = 0; k < kSteps; ++k) {
    series.innovation.row(k) *= scale(k);
    series.normalised_innovation[k] *= scale(k) * scale(k);
  }
  return series;
}

TEST(ResidualDiagnostics, AnIntermittentErrorFailsTheCountAboveTheBand) {
  // One step in 12 has innovations 1.6x what S says (NIS x2.56), the others 0.93x (x0.865):
  // the mean NIS stays within 1% of its expectation; about 8% of the steps lie above the band
  // where 2.5% are expected.
  const ResidualDiagnostics d = diagnose_residuals(
      rescaled(synthetic_series(11), [](int k) { return k % 12 == 0 ? 1.6 : 0.93; }), synthetic_points());
  EXPECT_FALSE(failed(d, "nis_mean")) << describe(d);
  EXPECT_TRUE(failed(d, "nis_above_band")) << describe(d);
}

TEST(ResidualDiagnostics, AnSThatOverstatesByAFewPercentPassesBothNisTests) {
  // The random-walk drift makes S a few percent conservative by design (nis_mean's low end
  // allows 10%); the steps it pushes below the band are not counted against the model.
  const ResidualDiagnostics d = diagnose_residuals(synthetic_series(12, 0.95), synthetic_points());
  EXPECT_FALSE(failed(d, "nis_mean")) << describe(d);
  EXPECT_FALSE(failed(d, "nis_above_band")) << describe(d);
}

TEST(ResidualDiagnostics, ATranslationOfEveryPointIsTheRigidPart) {
  const Eigen::Vector3d t(0.2e-3, -0.1e-3, 0.05e-3);   // well under the noise of one step
  Eigen::VectorXd offset(kRows);
  for (int j = 0; j < kResidualPoints; ++j) offset.segment<3>(3 * j) = t;
  const ResidualDiagnostics d = diagnose_residuals(synthetic_series(7, 1.0, 0.0, offset), synthetic_points());
  EXPECT_EQ(d.verdict.consistency, Consistency::inconsistent) << describe(d);
  EXPECT_TRUE(failed(d, "rigid_bias")) << describe(d);
  EXPECT_GT(d.spatial.rigid_share, 0.9) << describe(d);
  EXPECT_LT(d.spatial.deformation_rms, 0.3 * d.spatial.rigid_rms);
  EXPECT_LT((d.spatial.translation - t).norm(), 0.2 * t.norm()) << d.spatial.translation.transpose();
  EXPECT_LT(d.spatial.rotation.norm(), 2e-3) << "no rotation to speak of (rad)";
}

TEST(ResidualDiagnostics, BurnInMissingRowsAndTooFewSteps) {
  InnovationSeries series = synthetic_series(8);
  // A transient at the start, then every third step loses point 2: the burn-in removes the
  // first, the statistics skip the second.
  for (int k = 0; k < 50; ++k) series.innovation.row(k).array() += 5e-3;
  for (int k = 0; k < kSteps; k += 3) {
    series.innovation.block(k, 6, 1, 3).setConstant(NAN);
    series.innovation_std.block(k, 6, 1, 3).setConstant(NAN);
    series.observed_rows[static_cast<std::size_t>(k)] = kRows - 3;
    series.normalised_innovation[k] = 0.0;
    for (int i = 0; i < kRows; ++i)
      if (!std::isnan(series.innovation(k, i)))
        series.normalised_innovation[k] += std::pow(series.innovation(k, i) / series.innovation_std(k, i), 2);
  }
  ResidualDiagnosticsOptions options;
  options.burn_in_steps = 50;
  const ResidualDiagnostics d = diagnose_residuals(series, synthetic_points(), options);
  EXPECT_EQ(d.first_step, 51);
  EXPECT_EQ(d.verdict.consistency, Consistency::consistent) << describe(d);
  EXPECT_EQ(d.bias.count[6], (kSteps - 50) - (kSteps - 50 + 1) / 3) << "point 2 x: the steps it was seen";
  // Without the burn-in the transient shows.
  options.burn_in_steps = 0;
  EXPECT_EQ(diagnose_residuals(series, synthetic_points(), options).verdict.consistency, Consistency::inconsistent);
  // 5 steps of 36 rows: too few steps, and too few rows for the NIS alone (below).
  options.burn_in_steps = kSteps - 5;
  EXPECT_EQ(diagnose_residuals(series, synthetic_points(), options).verdict.consistency, Consistency::too_few_steps);
}

// A few scans of many points (the Truth Cube: 3 scans of 1029 rows): too few steps to follow
// a row, but the NIS over their rows still judges the model; only the NIS tests run.
TEST(ResidualDiagnostics, AFewStepsOfManyRowsAreJudgedByTheirNis) {
  ResidualDiagnosticsOptions options;
  options.burn_in_steps = kSteps - 10;   // 10 steps of 36 rows: 360 >= 300
  const ResidualDiagnostics consistent = diagnose_residuals(synthetic_series(21), synthetic_points(), options);
  EXPECT_TRUE(consistent.nis_only);
  EXPECT_EQ(consistent.verdict.consistency, Consistency::consistent) << describe(consistent);
  for (const DiagnosticTest& test : consistent.verdict.tests)
    EXPECT_TRUE(test.name == "nis_mean" || test.name == "nis_above_band") << test.name << " ran";
  // Innovations twice what S says fail, even over ten steps.
  const ResidualDiagnostics understated = diagnose_residuals(synthetic_series(21, 2.0), synthetic_points(), options);
  EXPECT_EQ(understated.verdict.consistency, Consistency::inconsistent) << describe(understated);
  EXPECT_TRUE(failed(understated, "nis_mean"));
  // Fewer rows than min_rows_of_few_steps: too few to judge.
  options.min_rows_of_few_steps = 400;
  EXPECT_EQ(diagnose_residuals(synthetic_series(21), synthetic_points(), options).verdict.consistency,
            Consistency::too_few_steps);
}

TEST(ResidualDiagnostics, CatchUpStepsAreLeftOut) {
  // A transient in the middle of the run (a cut the filter is catching up with): marked as a
  // catch-up it is left out and counted; unmarked it fails the verdict; a size that does not
  // match the steps is an error.
  InnovationSeries series = synthetic_series(9);
  for (int k = 250; k < 330; ++k) {
    series.innovation.row(k).array() += 3e-3;
    series.normalised_innovation[k] =
        (series.innovation.row(k).array() / series.innovation_std.row(k).array()).square().sum();
  }
  EXPECT_EQ(diagnose_residuals(series, synthetic_points()).verdict.consistency, Consistency::inconsistent);
  series.catching_up.assign(kSteps, false);
  for (int k = 250; k < 330; ++k) series.catching_up[static_cast<std::size_t>(k)] = true;
  series.catching_up[10] = true;   // inside the burn-in: not counted there
  const ResidualDiagnostics d = diagnose_residuals(series, synthetic_points());
  EXPECT_EQ(d.verdict.consistency, Consistency::consistent) << describe(d);
  EXPECT_EQ(d.catch_up_steps, 80);
  EXPECT_EQ(d.steps_used, kSteps - kSteps / 10 - 80);
  series.catching_up.pop_back();
  EXPECT_THROW(diagnose_residuals(series, synthetic_points()), std::invalid_argument);
}

// A real filter run: the box with the shipped noise (0.5 mm, the filter told the same) and
// the scenario's prior (2x off the truth), 100 steps, no cut. Short, to keep the suite fast:
// the diagnostics need steps, not convergence (the prior's spread is in S while it lasts).
struct BoxRunData {
  Scenario scenario;
  ObservationTable observations;
};

const BoxRunData& box_run_data() {
  static std::unique_ptr<BoxRunData> data;
  if (!data) {
    data = std::make_unique<BoxRunData>();
    data->scenario = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.json");
    data->scenario.events.clear();
    data->scenario.time.steps = 100;
    const fs::path dir = test::unique_temp_path("sigmafem_residual_diagnostics_test");
    GenerateOptions options;
    options.out_dir = dir.string();
    options.vtk_every = 0;
    std::ostringstream log;
    generate(data->scenario, options, log);
    data->observations = read_observations_csv((dir / "observations.csv").string(),
                                               static_cast<int>(data->scenario.observations.nodes.size()),
                                               data->scenario.time.dt);
    fs::remove_all(dir);
  }
  return *data;
}

ResidualDiagnostics diagnose_box(const Eigen::MatrixXd& points) {
  const BoxRunData& data = box_run_data();
  const Scenario& s = data.scenario;
  const EstimationOptions options = test::filter_options(s, SigmaPointSet::simplex, s.filter->observation_std);
  CpuEnsemble ensemble(make_model(s), s.filter->estimate, s.observations.nodes, 4);
  const EstimationRun run = run_estimation(ensemble, options, data.observations.times, data.observations.so, points, {});
  EXPECT_TRUE(run.complete) << run.stop_reason;
  return diagnose_residuals(innovation_series(run), mean_observed_positions(points));
}

TEST(ResidualDiagnosticsBox, DataTheModelExplainsAreConsistent) {
  const ResidualDiagnostics d = diagnose_box(box_run_data().observations.points);
  EXPECT_EQ(d.steps_used, 90);
  EXPECT_EQ(d.verdict.consistency, Consistency::consistent) << describe(d);
}

TEST(ResidualDiagnosticsBox, ACameraRegistrationErrorIsInconsistentAndRigid) {
  // Every observed point shifted by (0.2, 0.4, 0.4) mm, about the noise of one coordinate.
  // The filter bends the stiffnesses to explain it; over this short run what it cannot yet
  // explain stays mostly rigid: the rigid part is the larger (measured share 0.68 since the
  // filter re-samples the velocities too, which lets it bend the stiffnesses further in 100
  // steps; it was above 0.75 before). (Over the whole 1500 steps it bends them far enough that its own
  // wrong deformation dominates the mean residual, rigid share 0.21, README; the rigid
  // components' t-test still fails, at 12 against 3.6.)
  Eigen::MatrixXd points = box_run_data().observations.points;
  const Eigen::Vector3d offset(0.2e-3, 0.4e-3, 0.4e-3);
  for (Eigen::Index c = 0; c < points.cols(); c += 3)
    points.middleCols(c, 3).rowwise() += offset.transpose();
  const ResidualDiagnostics d = diagnose_box(points);
  EXPECT_EQ(d.verdict.consistency, Consistency::inconsistent) << describe(d);
  EXPECT_TRUE(failed(d, "rigid_bias")) << describe(d);
  RecordProperty("rigid_share", std::to_string(d.spatial.rigid_share));
  EXPECT_GT(d.spatial.rigid_share, 0.5) << "the rigid part dominates: " << describe(d);
  EXPECT_GT(d.spatial.translation.dot(offset), 0.0) << "in the direction of the offset";
}

}  // namespace
}  // namespace sigmafem
