// The synthetic-data generator: determinism (same seed, same bytes), the noise it adds, and
// the timing of events (a cut changes the data from its step on, and not before).
#include "temp_path.h"
#include "host/generator/generate.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "host/common/input_error.h"
#include "host/data/point_cloud_table.h"
#include "host/scenario/scenario.h"

namespace sigmafem {
namespace {
namespace fs = std::filesystem;

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Rows of a sigmafem CSV as numbers (comments and header skipped; empty fields NaN).
std::vector<std::vector<double>> read_rows(const fs::path& path) {
  std::ifstream in(path);
  std::vector<std::vector<double>> rows;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header) {
      header = false;
      continue;
    }
    std::vector<double> row;
    std::stringstream fields(line);
    std::string field;
    while (std::getline(fields, field, ',')) row.push_back(field.empty() ? NAN : std::stod(field));
    rows.push_back(row);
  }
  return rows;
}

class GenerateTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::unique_temp_path(std::string("sigmafem_generate_test_") +
                                  ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    scenario_ = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.json");
    scenario_.time.steps = 60;  // short runs: the properties do not depend on the length
  }
  void TearDown() override { fs::remove_all(dir_); }

  GenerateResult run(const std::string& sub, std::uint64_t seed, int vtk_every = 0) {
    GenerateOptions options;
    options.seed = seed;
    options.vtk_every = vtk_every;
    return run_with(sub, options);
  }
  // generate with `options` (faults, gaps, ...) into `sub`.
  GenerateResult run_with(const std::string& sub, GenerateOptions options) {
    options.out_dir = (dir_ / sub).string();
    std::ostringstream log;
    return generate(scenario_, options, log);
  }

  fs::path dir_;
  Scenario scenario_;
};

TEST_F(GenerateTest, SameSeedGivesSameBytesAndOtherSeedOtherNoise) {
  run("a", 7);
  run("b", 7);
  run("c", 8);
  EXPECT_EQ(read_text(dir_ / "a/observations.csv"), read_text(dir_ / "b/observations.csv"));
  EXPECT_EQ(read_text(dir_ / "a/truth.csv"), read_text(dir_ / "b/truth.csv"));
  EXPECT_NE(read_text(dir_ / "a/observations.csv"), read_text(dir_ / "c/observations.csv"))
      << "a different seed must give different noise";
}

TEST_F(GenerateTest, NoiseHasTheScenarioStandardDeviation) {
  scenario_.observations.noise_std = 0.0;
  run("clean", 1);
  scenario_.observations.noise_std = 0.002;
  run("noisy", 1);
  const auto clean = read_rows(dir_ / "clean/observations.csv");
  const auto noisy = read_rows(dir_ / "noisy/observations.csv");
  ASSERT_EQ(clean.size(), noisy.size());
  ASSERT_EQ(clean.size(), 61u) << "rows: the rest state and one per step";
  double sum = 0.0, sum_squares = 0.0;
  long count = 0;
  for (std::size_t k = 0; k < clean.size(); ++k) {
    for (std::size_t c = 0; c < 5; ++c)
      EXPECT_EQ(clean[k][c], noisy[k][c]) << "step, time and SO carry no noise (row " << k << ")";
    for (std::size_t c = 5; c < clean[k].size(); ++c) {
      const double e = noisy[k][c] - clean[k][c];
      sum += e;
      sum_squares += e * e;
      ++count;
    }
  }
  const double mean = sum / static_cast<double>(count);
  const double std_dev = std::sqrt(sum_squares / static_cast<double>(count) - mean * mean);
  // About 2200 samples: the sample std is within 5% of 2 mm with overwhelming probability.
  EXPECT_NEAR(std_dev, 0.002, 0.0001) << "noise standard deviation";
  EXPECT_NEAR(mean, 0.0, 0.0002) << "noise mean";
}

TEST_F(GenerateTest, CutChangesTheTrajectoryFromItsStepOnAndNotBefore) {
  scenario_.observations.noise_std = 0.0;
  scenario_.events.clear();
  run("uncut", 1);
  const int cut_step = 25;
  Event cut;
  cut.time = cut_step * scenario_.time.dt;
  cut.ligament = scenario_.ligament_index("middle");
  ASSERT_GE(cut.ligament, 0) << "box.json has a ligament called middle";
  cut.ligament_name = "middle";
  cut.stiffness = 0.01;
  scenario_.events = {cut};
  run("cut", 1);
  const auto uncut = read_rows(dir_ / "uncut/observations.csv");
  const auto with_cut = read_rows(dir_ / "cut/observations.csv");
  ASSERT_EQ(uncut.size(), with_cut.size());
  for (int k = 0; k < cut_step; ++k)
    EXPECT_EQ(uncut[k], with_cut[k]) << "row " << k << " is before the cut and must not change";
  for (std::size_t k = cut_step; k < uncut.size(); ++k)
    EXPECT_NE(uncut[k], with_cut[k]) << "row " << k << " is after the cut and must change";
  const auto truth = read_rows(dir_ / "cut/truth.csv");
  const std::size_t middle_column = 2 + static_cast<std::size_t>(cut.ligament);
  EXPECT_EQ(truth[cut_step - 1][middle_column], scenario_.ligaments[cut.ligament].stiffness);
  EXPECT_EQ(truth[cut_step][middle_column], 0.01) << "truth.csv records the cut at its step";
}

TEST_F(GenerateTest, VtkSeriesListsEveryFrame) {
  const GenerateResult result = run("vtk", 1, 20);
  EXPECT_EQ(result.vtk_frames, 4) << "frames at steps 0, 20, 40, 60";
  const std::string pvd = read_text(dir_ / "vtk" / (scenario_.name + ".pvd"));
  for (int f = 0; f < 4; ++f) {
    char name[64];
    std::snprintf(name, sizeof name, "vtk/%s_%06d.vtu", scenario_.name.c_str(), f);
    EXPECT_NE(pvd.find(name), std::string::npos) << "pvd lists " << name;
    EXPECT_TRUE(fs::exists(dir_ / "vtk" / name)) << name;
  }
  EXPECT_FALSE(fs::exists(dir_ / "vtk" / ".sigmafem-partial")) << "the staging folder is gone";
}

// A simulation whose solve breaks down (here a load that overflows: a scenario file cannot
// hold one, its numbers are bounded, but a program building a Scenario can) stops with the step
// and time, and writes nothing: no garbage trajectory under the final names.
TEST_F(GenerateTest, ADivergingSimulationNamesItsStepAndWritesNothing) {
  scenario_.gravity = Eigen::Vector3d(0.0, 0.0, -1e300);
  try {
    run("diverged", 1, 10);
    FAIL() << "generate completed on an overflowing load";
  } catch (const std::runtime_error& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("diverged at step 1 (t = 0.01 s)"), std::string::npos) << message;
    EXPECT_NE(message.find("residual is not finite"), std::string::npos) << message;
  }
  EXPECT_FALSE(fs::exists(dir_ / "diverged" / "observations.csv"));
  EXPECT_FALSE(fs::exists(dir_ / "diverged" / "truth.csv"));
  EXPECT_FALSE(fs::exists(dir_ / "diverged" / (scenario_.name + ".pvd")));
  EXPECT_FALSE(fs::exists(dir_ / "diverged" / ".sigmafem-partial")) << "the staging folder is removed";
}

// A surface cloud (observations.surface_cloud): pointcloud.csv holds one frame per step from
// step 1, the same bytes for the same seed; the noise is the scenario's (the points are drawn
// from their own stream, so a noise-free run samples the same places); dropouts thin the
// frames and are counted.
TEST_F(GenerateTest, SurfaceCloudsHaveAFramePerStepWithTheScenarioNoise) {
  scenario_ = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/liver_cloud.json");
  scenario_.time.steps = 20;
  scenario_.observations.noise_std = 0.0;
  run("clean", 4);
  scenario_.observations.noise_std = 0.001;
  run("noisy", 4);
  run("again", 4);
  EXPECT_EQ(read_text(dir_ / "noisy/pointcloud.csv"), read_text(dir_ / "again/pointcloud.csv"));
  const PointCloudTable clean = read_point_cloud_csv((dir_ / "clean/pointcloud.csv").string());
  const PointCloudTable noisy = read_point_cloud_csv((dir_ / "noisy/pointcloud.csv").string());
  ASSERT_EQ(clean.frames.size(), 20u);
  ASSERT_EQ(noisy.frames.size(), 20u);
  double sum_squares = 0.0;
  for (std::size_t f = 0; f < clean.frames.size(); ++f) {
    EXPECT_NEAR(clean.frames[f].time, 0.01 * static_cast<double>(f + 1), 1e-12);
    ASSERT_EQ(clean.frames[f].points.cols(), scenario_.observations.surface_cloud->points_per_frame);
    sum_squares += (noisy.frames[f].points - clean.frames[f].points).squaredNorm();
  }
  const double std_dev = std::sqrt(sum_squares / (3.0 * clean.point_count()));
  EXPECT_NEAR(std_dev, 0.001, 0.00005) << "18000 samples: the sample std within 5%";

  GenerateOptions options;
  options.vtk_every = 0;
  options.dropouts = 0.1;
  options.outliers = 0.05;
  const GenerateResult faulty = run_with("faulty", options);
  const PointCloudTable thinned = read_point_cloud_csv((dir_ / "faulty/pointcloud.csv").string());
  EXPECT_EQ(thinned.point_count(), clean.point_count() - faulty.dropouts);
  EXPECT_NEAR(faulty.dropouts, 0.1 * clean.point_count(), 5.0 * std::sqrt(0.09 * clean.point_count()));
  EXPECT_NEAR(faulty.outliers, 0.05 * clean.point_count(), 5.0 * std::sqrt(0.0475 * clean.point_count()));
}

// --gap-steps: a tracked point is lost for runs of steps of the given mean length, the
// missing share staying --dropouts. The liver's twelve points over 2000 steps: about 120 gaps.
TEST_F(GenerateTest, GapsLastTheirMeanLengthAndKeepTheMissingShare) {
  scenario_ = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/liver.json");
  scenario_.events.clear();
  GenerateOptions options;
  options.vtk_every = 0;
  options.dropouts = 0.1;
  options.gap_steps = 20.0;
  const GenerateResult result = run_with("gaps", options);
  const auto rows = read_rows(dir_ / "gaps" / "observations.csv");
  int gaps = 0, missing = 0, point_steps = 0;
  for (std::size_t p = 0; p < 12; ++p) {
    bool in_gap = false;
    for (std::size_t k = 1; k < rows.size(); ++k) {
      const bool lost = std::isnan(rows[k][5 + 3 * p]);
      gaps += lost && !in_gap;
      missing += lost;
      ++point_steps;
      in_gap = lost;
    }
  }
  EXPECT_EQ(missing, result.dropouts);
  EXPECT_NEAR(static_cast<double>(missing) / point_steps, 0.1, 0.03);
  EXPECT_NEAR(static_cast<double>(missing) / gaps, 20.0, 5.0) << gaps << " gaps";
  scenario_ = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/liver_cloud.json");
  EXPECT_THROW(run_with("cloud", options), InputError) << "a cloud's points have no identity to lose";
}

}  // namespace
}  // namespace sigmafem
