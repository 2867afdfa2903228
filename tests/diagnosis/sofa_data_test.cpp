// The filter and diagnose on data sigmafem did not make (issue 13): the positions SOFA printed
// for its run of the liver (../shared/data/sofa-reference: 1000 steps, ten monitored nodes
// every 10 steps, the three ligaments at 4000 N/m), with Gaussian noise added here (0.005 in
// the run's raw units, 0.5% of the largest displacement, 0.05% of the organ's size) and, for two cases, an effect
// the scenario does not declare: a camera offset added to the positions, or the positions
// shown 0.1 s late (each printed frame moved 10 steps on). The model is the scenario SOFA ran
// with a filter block added: the stiffnesses' prior median 1500 N/m, a factor e (1 std) wide.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>

#include "temp_path.h"
#include "host/diagnosis/diagnosis.h"
#include "host/scenario/scenario.h"

namespace sigmafem {
namespace {
namespace fs = std::filesystem;

constexpr double kNoise = 0.005;
constexpr double kTruth = 4000.0;

fs::path sofa_folder() { return fs::path(SIGMAFEM_SHARED_DIR) / "data" / "sofa-reference"; }

// SOFA's scenario with a filter block; its mesh and trajectory beside it, as its README asks.
Scenario sofa_scenario() {
  const fs::path dir = test::unique_temp_path("sigmafem_sofa_data_test");
  fs::create_directories(dir);
  nlohmann::json s;
  std::ifstream(sofa_folder() / "scenario.json") >> s;
  s["observations"]["noise_std"] = kNoise;
  s["filter"] = {{"estimate", {"l1", "l2", "l3"}},
                 {"initial_stiffness", {1500.0, 1500.0, 1500.0}},
                 {"initial_log_std", 1.0},
                 {"parameter_drift_log_std", 0.0},   // no cut in this run
                 {"observation_std", kNoise},
                 {"sigma_points", "simplex"}};
  std::ofstream(dir / "scenario.json") << s.dump();
  fs::copy_file(sofa_folder() / "traj.csv", dir / "traj.csv");
  fs::copy_file(fs::path(SIGMAFEM_SHARED_DIR) / "data" / "liver" / "liver.msh", dir / "liver.msh");
  Scenario scenario = load_scenario((dir / "scenario.json").string());
  fs::remove_all(dir);
  return scenario;
}

// The printed frames, by step: t = 0, 0.1, ..., 10 s, 30 numbers each.
std::map<int, Eigen::VectorXd> sofa_frames(double dt) {
  std::ifstream in(sofa_folder() / "sofa_monitor_10nodes.txt");
  std::map<int, Eigen::VectorXd> frames;
  std::string token;
  int step = -1, filled = 0;
  while (in >> token) {
    if (token == "T=") {
      double t = 0.0;
      in >> t;
      step = static_cast<int>(std::lround(t / dt));
      frames[step] = Eigen::VectorXd::Zero(30);
      filled = 0;
    } else if (token != "X=" && step >= 0 && filled < 30) {
      frames[step][filled++] = std::stod(token);
    }
  }
  return frames;
}

// Every step of the run with the SO position; the printed frames observed (`lag_steps` late,
// plus `offset`, plus noise), the other rows missing.
ObservationTable sofa_data(const Scenario& scenario, const Eigen::Vector3d& offset, int lag_steps, unsigned seed) {
  const std::map<int, Eigen::VectorXd> frames = sofa_frames(scenario.time.dt);
  const int steps = scenario.time.steps;
  ObservationTable data;
  data.so.resize(steps + 1, 3);
  data.points = Eigen::MatrixXd::Constant(steps + 1, 30, NAN);
  std::mt19937_64 random(seed);
  std::normal_distribution<double> noise(0.0, kNoise);
  for (int k = 0; k <= steps; ++k) {
    const double t = k * scenario.time.dt;
    data.steps.push_back(k);
    data.times.push_back(t);
    data.so.row(k) = scenario.control.trajectory.position(t, scenario.control.start).transpose();
    if (frames.count(k) == 0) continue;
    const Eigen::VectorXd& seen = frames.at(std::max(0, k - lag_steps));
    for (int i = 0; i < 30; ++i) data.points(k, i) = seen[i] + offset[i % 3] + noise(random);
  }
  return data;
}

DiagnoseOptions diagnose_options() {
  DiagnoseOptions options;
  // The CPU back end, with a factor per sigma point, runs a diagnosis of these 1000 steps
  // (three candidates) in about 9 s alone on the 2-core machine (stop 31).
  options.backend = "cpu";
  options.candidates = {"gravity", "camera_offset", "time_lag"};
  return options;
}

void expect_stiffnesses_found(const ModelFit& fit, const std::string& label) {
  for (Eigen::Index l = 0; l < fit.stiffness.size(); ++l) {
    std::cout << label << ": " << fit.ligaments[static_cast<std::size_t>(l)] << " " << fit.stiffness[l] << " +- "
              << fit.stiffness_std[l] << " N/m (truth 4000)\n";
    // Within 3 of its std, and within 10% of the truth (the middle ligament, l2, is the least
    // observed: its std is 6% of its value at twice this noise).
    EXPECT_LT(std::abs(fit.stiffness[l] / kTruth - 1.0), 0.10) << label << ", ligament " << l;
    EXPECT_LT(std::abs(fit.stiffness[l] - kTruth), 3.0 * fit.stiffness_std[l]) << label << ", ligament " << l;
  }
}

TEST(SofaData, TheFilterFindsTheLigamentsInAnotherSimulatorsRunAndCallsItConsistent) {
  const Scenario scenario = sofa_scenario();
  for (unsigned seed : {1u, 2u}) {
    const Diagnosis d = diagnose(scenario, sofa_data(scenario, Eigen::Vector3d::Zero(), 0, seed), std::nullopt,
                                 diagnose_options());
    EXPECT_EQ(d.outcome, DiagnosisOutcome::consistent) << "seed " << seed << ": " << d.conclusion;
    EXPECT_EQ(d.fits.size(), 1u) << "nothing to look for";
    expect_stiffnesses_found(d.before(), "SOFA, seed " + std::to_string(seed));
  }
}

// Diagnose on SOFA's data with `offset` or `lag_steps` undeclared must name exactly `effect`
// and find it within 10% (or 3 of its stated std per number), the stiffnesses then as above.
void expect_named(const std::string& effect, const std::vector<double>& truth, const Eigen::Vector3d& offset,
                  int lag_steps) {
  Scenario scenario = sofa_scenario();
  // The pull (5 s) and 1 s of the hold: the rest of the hold adds little but time.
  scenario.time.steps = 600;
  const Diagnosis d =
      diagnose(scenario, sofa_data(scenario, offset, lag_steps, 3), std::nullopt, diagnose_options());
  ASSERT_EQ(d.outcome, DiagnosisOutcome::explained) << d.conclusion;
  ASSERT_EQ(d.discovered.size(), 1u) << d.conclusion;
  EXPECT_EQ(d.discovered[0].name, effect) << d.conclusion;
  const EffectEstimate& e = d.after().estimates[0];
  double error2 = 0.0, norm2 = 0.0;
  bool within_std = true;
  for (std::size_t j = 0; j < truth.size(); ++j) {
    error2 += std::pow(e.value[j] - truth[j], 2);
    norm2 += truth[j] * truth[j];
    within_std = within_std && std::abs(e.value[j] - truth[j]) <= 3.0 * e.std[j];
  }
  std::cout << "SOFA, " << effect << ": off by " << 100.0 * std::sqrt(error2 / norm2) << "%; " << d.conclusion << "\n";
  EXPECT_TRUE(std::sqrt(error2 / norm2) <= 0.1 || within_std) << d.conclusion;
  expect_stiffnesses_found(d.after(), "SOFA with " + effect);
}

TEST(SofaData, DiagnoseNamesAnUndeclaredCameraOffset) {
  expect_named("camera_offset", {0.1, -0.05, 0.05}, Eigen::Vector3d(0.1, -0.05, 0.05), 0);
}

TEST(SofaData, DiagnoseNamesAnUndeclaredTimeLag) {
  expect_named("time_lag", {0.1}, Eigen::Vector3d::Zero(), 10);
}

}  // namespace
}  // namespace sigmafem
