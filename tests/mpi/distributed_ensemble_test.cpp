// The sigma points over MPI ranks (issue 19): `mpirun -n R sigmafem estimate` on 1, 2 and 3
// ranks of this machine (oversubscribed: more ranks than cores), its results against one
// process's, and ranks that fail. A short liver run (400 steps, the cut at 2.5 s) keeps each
// command to a few seconds.
#include "host/mpi/distributed_ensemble.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "cli/sigmafem_command.h"
#include "requirement.h"
#include "scenario_directory.h"
#include "temp_path.h"

namespace sigmafem {
namespace {
namespace fs = std::filesystem;
using nlohmann::json;
using test::CommandRun;
using test::run_sigmafem_command;

// mpirun as the tests run it: as root where they run as root (CI, the fresh machine), more
// ranks than cores, no shared-memory single copy (refused in some containers), and a time
// limit so that a hang fails the test instead of holding the suite.
std::string mpirun(int ranks) {
  return std::string("OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
                     "OMPI_MCA_rmaps_base_oversubscribe=1 OMPI_MCA_btl_vader_single_copy_mechanism=none "
                     "timeout 300 ") +
         SIGMAFEM_MPIEXEC + " -n " + std::to_string(ranks) + " ";
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// The last row's estimates (the columns named in `names`) of an estimates.csv.
std::vector<double> final_estimates(const fs::path& path, const std::vector<std::string>& names) {
  std::ifstream in(path);
  std::string line, header, last;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    if (header.empty()) header = line;
    else last = line;
  }
  auto split = [](const std::string& text) {
    std::vector<std::string> fields;
    std::stringstream stream(text);
    for (std::string field; std::getline(stream, field, ',');) fields.push_back(field);
    return fields;
  };
  const std::vector<std::string> columns = split(header), values = split(last);
  std::vector<double> found;
  for (const std::string& name : names)
    for (std::size_t c = 0; c < columns.size(); ++c)
      if (columns[c] == name) found.push_back(std::stod(values.at(c)));
  return found;
}

class DistributedEstimation : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    directory_ = std::make_unique<test::TempDir>("sigmafem_mpi");
    // The liver, 400 steps with the cut at 2.5 s, its files found where the shipped one is.
    json scenario = json::parse(read_file(kScenarios + "liver.json"));
    scenario["time"]["steps"] = 400;
    scenario["events"][0]["time"] = 2.5;
    scenario["mesh"]["file"] = kScenarios + "liver.msh";
    scenario["control"]["trajectory"]["file"] = kScenarios + "liver_trajectory.csv";
    scenario["output"]["vtk_every"] = 0;
    scenario_ = (fs::path(directory_->path()) / "liver_short.json").string();
    std::ofstream(scenario_) << scenario.dump(2);
    data_ = (fs::path(directory_->path()) / "data").string();
    const CommandRun generate = test::run_sigmafem("generate " + scenario_ + " --out " + data_ + " --quiet");
    ASSERT_EQ(generate.exit_code, 0) << generate.output;
    // For lavapipe (about 50 ms a liver filter step): 60 steps.
    scenario["time"]["steps"] = 60;
    scenario["events"][0]["time"] = 0.4;
    short_scenario_ = (fs::path(directory_->path()) / "liver_60.json").string();
    std::ofstream(short_scenario_) << scenario.dump(2);
    short_data_ = (fs::path(directory_->path()) / "data_60").string();
    const CommandRun shorter = test::run_sigmafem("generate " + short_scenario_ + " --out " + short_data_ + " --quiet");
    ASSERT_EQ(shorter.exit_code, 0) << shorter.output;
  }
  static void TearDownTestSuite() { directory_.reset(); }

  void SetUp() override {
    if (std::string(SIGMAFEM_MPIEXEC).empty()) SIGMAFEM_MISSING("this build has no MPI (libopenmpi-dev)");
  }

  // `sigmafem estimate` of the short liver into OUT/name, on `ranks` ranks (0: no mpirun).
  CommandRun estimate(int ranks, const std::string& name, const std::string& options,
                      const std::string& environment = "", bool sixty_steps = false) {
    const std::string out = (fs::path(directory_->path()) / name).string();
    const std::string command = std::string(SIGMAFEM_BINARY) + " estimate " +
                                (sixty_steps ? short_scenario_ : scenario_) + " --data " +
                                (sixty_steps ? short_data_ : data_) + " --out " + out + " --quiet " + options;
    return run_sigmafem_command(environment + " " + (ranks > 0 ? mpirun(ranks) : std::string()) + command);
  }
  fs::path out(const std::string& name) const { return fs::path(directory_->path()) / name; }

  static inline std::unique_ptr<test::TempDir> directory_;
  static inline std::string scenario_, data_, short_scenario_, short_data_;
};

// The CPU back end: rank 0 re-samples all S in sigma order with the CPU back end's own code,
// and every sigma point's simulation is independent of the others', so the estimates are the
// same bits on one process and on 1, 2 and 3 ranks, for both sigma-point sets.
TEST_F(DistributedEstimation, TheCpuBackEndGivesTheSameBitsOnOneTwoAndThreeRanks) {
  for (const std::string set : {"simplex", "star"}) {
    const std::string options = "--backend cpu --sigma " + set;
    const CommandRun single = estimate(0, "cpu_" + set + "_single", options);
    ASSERT_EQ(single.exit_code, 0) << single.output;
    const std::string expected = read_file(out("cpu_" + set + "_single") / "estimates.csv");
    ASSERT_FALSE(expected.empty());
    for (int ranks : {1, 2, 3}) {
      const std::string name = "cpu_" + set + "_" + std::to_string(ranks);
      const CommandRun run = estimate(ranks, name, options);
      ASSERT_EQ(run.exit_code, 0) << run.output;
      EXPECT_EQ(read_file(out(name) / "estimates.csv"), expected) << set << " on " << ranks << " ranks";
      const json summary = json::parse(read_file(out(name) / "summary.json"));
      EXPECT_TRUE(summary["complete"].get<bool>());
      if (ranks > 1) {
        EXPECT_EQ(summary["observations"]["mpi_ranks"].get<int>(), ranks);
      }
    }
  }
}

// A device back end: over two or more ranks the re-centring is rank 0's, in double precision,
// where one process runs the device's float32 kernel; so 2 and 3 ranks give the same bits, and
// one process the same estimates within float32's reach (measured on the full liver run,
// 2000 steps, OpenCL with Jacobi: 0.41% at most along the run, 0.13% from the CPU back end
// over two ranks against 0.40% for one process).
TEST_F(DistributedEstimation, OpenClOnTwoAndThreeRanksGivesTheSameBitsAndOneProcesssEstimates) {
  const std::string options = "--backend opencl --preconditioner jacobi";
  const CommandRun single = estimate(0, "opencl_single", options);
  if (single.exit_code == 3) SIGMAFEM_MISSING("no OpenCL device: " << single.output);
  ASSERT_EQ(single.exit_code, 0) << single.output;
  for (int ranks : {2, 3}) {
    const CommandRun run = estimate(ranks, "opencl_" + std::to_string(ranks), options);
    ASSERT_EQ(run.exit_code, 0) << run.output;
  }
  EXPECT_EQ(read_file(out("opencl_2") / "estimates.csv"), read_file(out("opencl_3") / "estimates.csv"));
  const std::vector<std::string> names = {"left", "middle", "right"};
  const std::vector<double> one = final_estimates(out("opencl_single") / "estimates.csv", names);
  const std::vector<double> two = final_estimates(out("opencl_2") / "estimates.csv", names);
  ASSERT_EQ(one.size(), 3u);
  ASSERT_EQ(two.size(), 3u);
  for (std::size_t j = 0; j < 3; ++j) {
    std::printf("opencl, %s: one process %.6g N/m, two ranks %.6g N/m\n", names[j].c_str(), one[j], two[j]);
    EXPECT_NEAR(two[j], one[j], 0.01 * one[j]) << names[j];
  }
}

// Vulkan's share on every rank too (lavapipe is slow: 60 steps, two ranks against one process).
TEST_F(DistributedEstimation, VulkanOnTwoRanksGivesOneProcesssEstimates) {
  const CommandRun single = estimate(0, "vulkan_single", "--backend vulkan", "", true);
  if (single.exit_code == 3) SIGMAFEM_MISSING("no Vulkan device: " << single.output);
  ASSERT_EQ(single.exit_code, 0) << single.output;
  const CommandRun run = estimate(2, "vulkan_2", "--backend vulkan", "", true);
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const std::vector<std::string> names = {"left", "middle", "right"};
  const std::vector<double> one = final_estimates(out("vulkan_single") / "estimates.csv", names);
  const std::vector<double> two = final_estimates(out("vulkan_2") / "estimates.csv", names);
  ASSERT_EQ(two.size(), 3u);
  for (std::size_t j = 0; j < 3; ++j) EXPECT_NEAR(two[j], one[j], 0.01 * one[j]) << names[j];
}

// A rank that cannot make its share (here rank 2 is given a device that is not there, by
// mpirun's per-rank command lines): every rank says so and ends with the device error's code,
// and nothing is written.
TEST_F(DistributedEstimation, ARankThatCannotMakeItsShareStopsEveryRankWithItsError) {
  const std::string out_dir = out("no_share").string();
  const std::string command = std::string(SIGMAFEM_BINARY) + " estimate " + scenario_ + " --data " + data_ +
                              " --out " + out_dir + " --quiet --backend cpu";
  const CommandRun run = run_sigmafem_command(mpirun(2) + command + " : -n 1 " + std::string(SIGMAFEM_BINARY) +
                                              " estimate " + scenario_ + " --data " + data_ + " --out " + out_dir +
                                              " --quiet --backend opencl --device 9");
  EXPECT_EQ(run.exit_code, 3) << run.output;
  EXPECT_NE(run.output.find("sigmafem (rank 2 of 3): device error: no OpenCL device 9"), std::string::npos) << run.output;
  for (int rank : {0, 1})
    EXPECT_NE(run.output.find("sigmafem (rank " + std::to_string(rank) + " of 3): device error: rank 2: no OpenCL device 9"),
              std::string::npos)
        << run.output;
  EXPECT_FALSE(fs::exists(out_dir));
}

// A rank that fails in the middle of the run: rank 0 ends the run there, incomplete, as a
// failing step does on one process; every rank ends with an error that names the rank.
TEST_F(DistributedEstimation, ARankThatFailsMidRunEndsTheRunOnEveryRank) {
  for (int failing : {2, 0}) {
    const std::string name = "fails_" + std::to_string(failing);
    const CommandRun run =
        estimate(3, name, "--backend cpu", "SIGMAFEM_FAIL_RANK=" + std::to_string(failing) + ":20");
    EXPECT_EQ(run.exit_code, 1) << run.output;
    const json summary = json::parse(read_file(out(name) / "summary.json"));
    EXPECT_FALSE(summary["complete"].get<bool>());
    const std::string reason = summary["stop_reason"].get<std::string>();
    EXPECT_NE(reason.find("step 20:"), std::string::npos) << reason;
    EXPECT_NE(reason.find("failed in advance 20 as SIGMAFEM_FAIL_RANK asks"), std::string::npos) << reason;
    if (failing != 0) {
      EXPECT_NE(reason.find("rank 2: "), std::string::npos) << reason;
    }
    for (int rank : {1, 2})
      EXPECT_NE(run.output.find("sigmafem (rank " + std::to_string(rank) + " of 3): failed: "), std::string::npos)
          << run.output;
  }
}

// A rank that dies (a crash): mpirun ends the whole job, which does not hang.
TEST_F(DistributedEstimation, ARankThatCrashesEndsTheJob) {
  const CommandRun run = estimate(2, "crash", "--backend cpu", "SIGMAFEM_FAIL_RANK=1:20:abort");
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.exit_code, 124) << "timed out: " << run.output;
  EXPECT_FALSE(fs::exists(out("crash") / "summary.json"));
}

TEST_F(DistributedEstimation, MoreRanksThanSigmaPointsAndOtherCommandsAreRefusedOnEveryRank) {
  const CommandRun run = estimate(5, "too_many", "--backend cpu");
  EXPECT_EQ(run.exit_code, 2) << run.output;
  for (int rank = 0; rank < 5; ++rank)
    EXPECT_NE(run.output.find("sigmafem (rank " + std::to_string(rank) + " of 5): error: 5 MPI ranks for 4 sigma "
                              "points: every rank needs at least one"),
              std::string::npos)
        << run.output;
  const CommandRun demo = run_sigmafem_command(mpirun(2) + std::string(SIGMAFEM_BINARY) + " info " + scenario_);
  EXPECT_EQ(demo.exit_code, 2) << demo.output;
  EXPECT_NE(demo.output.find("info runs on one process; over MPI ranks only estimate runs"), std::string::npos)
      << demo.output;
}

}  // namespace
}  // namespace sigmafem
