// The Vulkan device layer: device listing, failures as DeviceErrors that say what to do (a
// shader that fails to load, an ensemble too big for the device, said before allocating),
// and the validation layer, where it is installed, reporting nothing on a whole filter cycle.
#include "host/vulkan/vulkan_device.h"

#include <Eigen/LU>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "device_layout.h"
#include "host/engine/make_ensemble.h"
#include "host/ensemble/device_limits.h"
#include "host/model/model.h"
#include "host/scenario/scenario.h"
#include "host/vulkan/vulkan_ensemble.h"
#include "background_making_runs.h"
#include "requirement.h"
#include "tests/refined_liver.h"
#include "tests/scenario_directory.h"

namespace sigmafem {
namespace {

// Every test in a process run with SIGMAFEM_VULKAN_VALIDATION=1 (the ctest `vulkan_validation`
// in tests/CMakeLists.txt) must leave the validation layer silent: checked once at the end.
class VulkanValidationEnvironment : public ::testing::Environment {
 public:
  void TearDown() override {
    EXPECT_EQ(vulkan_validation_message_count(), 0)
        << "the Vulkan validation layer reported problems (printed above on stderr)";
  }
};
::testing::Environment* const validation_environment =
    ::testing::AddGlobalTestEnvironment(new VulkanValidationEnvironment);

class VulkanDeviceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    if (list_vulkan_devices(&why).empty()) SIGMAFEM_MISSING(why);
  }
};

TEST_F(VulkanDeviceTest, ListsDevicesWithTheirProperties) {
  const auto devices = list_vulkan_devices();
  ASSERT_FALSE(devices.empty());
  for (std::size_t i = 0; i < devices.size(); ++i) {
    EXPECT_EQ(devices[i].index, static_cast<int>(i));
    EXPECT_FALSE(devices[i].name.empty());
    EXPECT_FALSE(devices[i].type.empty());
    EXPECT_GT(devices[i].memory, 0u);
    EXPECT_GT(devices[i].max_buffer, 0u);
  }
}

TEST_F(VulkanDeviceTest, NoSuchDeviceSaysHowManyThereAre) {
  try {
    VulkanDevice device(99, Precision::single);
    FAIL() << "expected no device 99";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("no Vulkan device 99"), std::string::npos) << e.what();
  }
}

TEST_F(VulkanDeviceTest, AShaderThatFailsToLoadIsADeviceError) {
  VulkanDevice device(0, Precision::single);
  // Not SPIR-V: the driver never sees it (some crash on such input).
  const std::vector<std::uint32_t> garbage = {0xdeadbeef, 1, 2, 3, 4, 5};
  try {
    device.kernel_from_spirv("garbage", garbage.data(), garbage.size(), 1);
    FAIL() << "expected a load failure";
  } catch (const DeviceError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("failed to load"), std::string::npos) << message;
    EXPECT_NE(message.find("garbage"), std::string::npos) << message;
  }
  // A shader the build did not embed.
  try {
    device.kernel("no_such_shader", 1);
    FAIL() << "expected a missing shader";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_shader"), std::string::npos) << e.what();
  }
}

TEST_F(VulkanDeviceTest, TooBigAnEnsembleSaysHowMuchItNeeds) {
  const Scenario scenario = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.json");
  const Model model = make_model(scenario);
  // 1344 tetrahedra x 12 x S floats in one buffer: S = 2^22 needs about 270 GB (and the host's
  // per-sigma step constants, made before the check, 0.7 GB; at 2^26 they took 6-14 s).
  try {
    VulkanEnsemble ensemble(model, {0}, {}, 1 << 22, DeviceOptions{});
    FAIL() << "expected an out-of-memory error";
  } catch (const DeviceError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("out of device memory"), std::string::npos) << message;
    EXPECT_NE(message.find("MiB"), std::string::npos) << message;
  }
}

// A filter cycle through every shader and every host path (advance with several CG batches,
// observations, re-centring, the read-outs) in both precisions, and in float32 in both forms
// of the shaders too (texel reads, the CPU form; storage reads, the GPU form). Under the ctest
// `vulkan_validation` the layer watches it (synchronization validation included) and the
// environment above fails the run on any message; elsewhere it checks the results are finite.
TEST_F(VulkanDeviceTest, AFilterCycleRunsCleanly) {
  if (!vulkan_validation_available()) {
    // The ctest `vulkan_validation` asks for the layer: under the test command its absence fails.
    if (std::getenv("SIGMAFEM_VULKAN_VALIDATION") != nullptr && test::requirements_enforced())
      FAIL() << "SIGMAFEM_VULKAN_VALIDATION=1 but the layer VK_LAYER_KHRONOS_validation is not there "
                "(apt-get install vulkan-validationlayers)";
    std::cout << "validation layer off (SIGMAFEM_VULKAN_VALIDATION=1 and "
                 "VK_LAYER_KHRONOS_validation switch it on)\n";
  }
  const Scenario scenario = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.json");
  const Model model = make_model(scenario);
  const std::vector<int>& estimated = scenario.filter->estimate;
  const int p = static_cast<int>(estimated.size()), S = p + 1;
  const bool cpu_device = list_vulkan_devices()[0].type == "cpu";
  for (int run = 0; run < 3; ++run) {
    DeviceOptions options;
    options.precision = run == 2 ? Precision::double_precision : Precision::single;
    options.kernel_form = run == 1 ? (cpu_device ? KernelForm::gpu : KernelForm::cpu) : KernelForm::automatic;
    if (options.precision == Precision::double_precision && !list_vulkan_devices()[0].has_fp64) continue;
    VulkanEnsemble ensemble(model, estimated, scenario.observations.nodes, S, options);
    // Texel reads: the automatic form on a CPU device, the CPU form forced on a GPU.
    EXPECT_EQ(ensemble.texel_reads(), run == 1 ? !cpu_device : cpu_device) << "run " << run;
    Eigen::MatrixXd theta(p, S);
    for (int j = 0; j < p; ++j)
      for (int s = 0; s < S; ++s)
        theta(j, s) = std::log(model.ligaments[estimated[j]].stiffness) + 0.2 * std::sin(s + j);
    ensemble.set_parameters(theta);
    Eigen::MatrixXd y;
    for (int k = 1; k <= 3; ++k) {
      const StepReport report = ensemble.advance(
          scenario.control.trajectory.position(k * scenario.time.dt, scenario.control.start));
      EXPECT_EQ(report.unconverged_count(), 0);
      ensemble.predicted_observations(y);
      Recentering r;
      r.alpha = 1.0 / S;
      r.directions = Eigen::MatrixXd::Zero(p, S);
      for (int j = 0; j < p; ++j) {
        r.directions(j, j) = 1.0;
        r.directions(j, S - 1) = -1.0;
      }
      r.correction = Eigen::VectorXd::Zero(p);
      r.factor = Eigen::MatrixXd::Identity(p, p);
      ensemble.recenter(r);
    }
    ensemble.predicted_observations(y);
    EXPECT_TRUE(y.allFinite());
    EXPECT_TRUE(ensemble.positions(0).allFinite());
    const std::vector<double> frames = ensemble.frames(S - 1);
    EXPECT_EQ(static_cast<int>(frames.size()), 9 * model.element_count());
    // Each a rotation, the third row too, which the shaders do not keep (frames() makes it as
    // they do): rows orthonormal to float32 rounding, determinant +1.
    double worst = 0.0;
    for (std::size_t at = 0; at < frames.size(); at += 9) {
      const Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> F(&frames[at]);
      worst = std::max({worst, (F * F.transpose() - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff(),
                        std::abs(F.determinant() - 1.0)});
    }
    EXPECT_LT(worst, 1e-5) << "run " << run;
    const Eigen::MatrixXd Ad = ensemble.system_product(Eigen::MatrixXd::Ones(model.dof_count(), S));
    EXPECT_TRUE(Ad.allFinite());
  }
}

// SIGMAFEM_VULKAN_PROFILE: every shader's dispatches timed on the device and listed on stderr
// when the device goes, with the time between them.
TEST_F(VulkanDeviceTest, TheProfileListsEveryShadersDispatches) {
  const Scenario scenario = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.json");
  const Model model = make_model(scenario);
  const char* before = std::getenv("SIGMAFEM_VULKAN_PROFILE");
  const std::string saved = before ? before : "";
  setenv("SIGMAFEM_VULKAN_PROFILE", "1", 1);
  testing::internal::CaptureStderr();
  {
    VulkanEnsemble ensemble(model, scenario.filter->estimate, scenario.observations.nodes, 2, DeviceOptions{});
    const StepReport report = ensemble.advance(
        scenario.control.trajectory.position(scenario.time.dt, scenario.control.start));
    EXPECT_EQ(report.unconverged_count(), 0);
  }
  const std::string printed = testing::internal::GetCapturedStderr();
  if (before) setenv("SIGMAFEM_VULKAN_PROFILE", saved.c_str(), 1); else unsetenv("SIGMAFEM_VULKAN_PROFILE");
  EXPECT_NE(printed.find("Vulkan shader times on"), std::string::npos) << printed;
  // (CG's shaders are named by how a device runs it: cg_start, or cg_start_partials on a GPU.)
  for (const char* shader : {"  element_rhs", "  node_rhs", "  element_product", "  cg_start", "  state_update"})
    EXPECT_NE(printed.find(shader), std::string::npos) << shader << "\n" << printed;
  EXPECT_NE(printed.find("between dispatches"), std::string::npos) << printed;
  EXPECT_EQ(printed.find("nan"), std::string::npos) << printed;
}

// CG in two dispatches an iteration (cg_node_iteration forms q = A d from the element
// products) does what node_product and cg_iteration do, in the same order: the same bits.
TEST_F(VulkanDeviceTest, CgInTwoDispatchesGivesTheBitsOfThree) {
  const Scenario scenario = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.json");
  const Model model = make_model(scenario);
  const std::vector<int>& estimated = scenario.filter->estimate;
  const int p = static_cast<int>(estimated.size()), S = p + 1;
  Eigen::MatrixXd theta(p, S);
  for (int j = 0; j < p; ++j)
    for (int s = 0; s < S; ++s)
      theta(j, s) = std::log(model.ligaments[estimated[j]].stiffness) + 0.3 * std::cos(s + 2 * j);
  DeviceOptions three;
  three.node_iteration_work = 0;
  VulkanEnsemble two_dispatches(model, estimated, scenario.observations.nodes, S, DeviceOptions{});
  VulkanEnsemble three_dispatches(model, estimated, scenario.observations.nodes, S, three);
  ASSERT_TRUE(two_dispatches.node_iteration()) << "the box at S = 4 takes two dispatches by default";
  ASSERT_FALSE(three_dispatches.node_iteration());
  two_dispatches.set_parameters(theta);
  three_dispatches.set_parameters(theta);
  for (int k = 1; k <= 8; ++k) {
    const Eigen::Vector3d so = scenario.control.trajectory.position(k * scenario.time.dt, scenario.control.start);
    const StepReport a = two_dispatches.advance(so);
    const StepReport b = three_dispatches.advance(so);
    EXPECT_EQ(a.unconverged_count(), 0);
    EXPECT_EQ(a.cg_iterations, b.cg_iterations) << "step " << k;
  }
  for (int s = 0; s < S; ++s) {
    EXPECT_TRUE(two_dispatches.positions(s) == three_dispatches.positions(s)) << "sigma point " << s;
    EXPECT_TRUE(two_dispatches.velocities(s) == three_dispatches.velocities(s)) << "sigma point " << s;
  }
}

// The element and node shaders four sigma points a lane (kernels/vulkan/sigma_quads.h; S a
// multiple of 4, the CPU form) do per component what the one-a-lane shaders do: the same bits,
// with the QR and the polar frames (its selects per component), in float and double, at S = 8
// (two quads an element), node_product's quads too with the QR frames (three dispatches an
// iteration); at S = 6 the ensemble keeps one a lane.
TEST_F(VulkanDeviceTest, ElementShadersOnSigmaQuadsGiveTheBitsOfOneALane) {
  Scenario scenario = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/liver.json");
  const std::vector<int>& estimated = scenario.filter->estimate;
  for (const ElementRotation rotation : {ElementRotation::qr, ElementRotation::polar}) {
    scenario.material.rotation = rotation;
    const Model model = make_model(scenario);
    for (const Precision precision : {Precision::single, Precision::double_precision})
    for (const long long node_iteration_work : {kNodeIterationWork, 0LL}) {
      if (node_iteration_work == 0 && rotation == ElementRotation::polar) continue;
      const std::string what = std::string(rotation == ElementRotation::polar ? "polar" : "qr") +
                               (precision == Precision::single ? ", float" : ", double") +
                               (node_iteration_work == 0 ? ", node_product" : "");
      DeviceOptions quads, lanes;
      quads.precision = lanes.precision = precision;
      quads.node_iteration_work = lanes.node_iteration_work = node_iteration_work;
      lanes.sigma_quads = false;
      const int S = 8;
      VulkanEnsemble by_quads(model, estimated, scenario.observations.nodes, S, quads);
      VulkanEnsemble by_lanes(model, estimated, scenario.observations.nodes, S, lanes);
      ASSERT_TRUE(by_quads.sigma_quads()) << what;
      ASSERT_FALSE(by_lanes.sigma_quads()) << what;
      const Eigen::MatrixXd theta = test::spread_log_stiffness(scenario, model, S, 0.3);
      by_quads.set_parameters(theta);
      by_lanes.set_parameters(theta);
      for (int k = 1; k <= 6; ++k) {
        const Eigen::Vector3d so = scenario.control.trajectory.position(k * scenario.time.dt, scenario.control.start);
        const StepReport a = by_quads.advance(so);
        const StepReport b = by_lanes.advance(so);
        EXPECT_EQ(a.unconverged_count(), 0) << what;
        EXPECT_EQ(a.cg_iterations, b.cg_iterations) << what << ", step " << k;
      }
      for (int s = 0; s < S; ++s) {
        EXPECT_TRUE(by_quads.positions(s) == by_lanes.positions(s)) << what << ", sigma point " << s;
        EXPECT_TRUE(by_quads.velocities(s) == by_lanes.velocities(s)) << what << ", sigma point " << s;
      }
    }
  }
  const Model model = make_model(scenario);
  VulkanEnsemble six(model, estimated, scenario.observations.nodes, 6, DeviceOptions{});
  EXPECT_FALSE(six.sigma_quads()) << "S = 6 is not a multiple of 4";
}

// The CG shaders with lanes over sigma points (on a CPU device: each lane walks its sigma
// point's rows, or every J-th node of them, and sums in node order, J parts added by subgroup
// shuffles) against a work-group a sigma point (its tree of sums): the same steps to their
// rounding, in float and double, at S = 17 (a lane a sigma point: two full groups of 8 and one
// of one lane, seven past S) and S = 4 (with 8-lane shuffles, J = 2 lanes a sigma point), in
// the two dispatches an iteration and the three, over 40 steps. The sums' order differs, so the
// bits may: CG's iterations within one a step, the positions within 2e-7 m in float (1e-14 m in
// double) of each other (measured: 3e-8 and 3e-17), where the steps move the nodes by half a
// millimetre.
TEST_F(VulkanDeviceTest, CgWithASigmaPointALaneFollowsAGroupASigmaPoint) {
  Scenario scenario = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/liver.json");
  const std::vector<int>& estimated = scenario.filter->estimate;
  const Model model = make_model(scenario);
  for (const Precision precision : {Precision::single, Precision::double_precision}) {
    for (const int S : {17, 4}) {
      for (const long long node_iteration_work : {kNodeIterationWork, 0LL}) {
        const std::string what = std::string(precision == Precision::single ? "float" : "double") +
                                 ", S = " + std::to_string(S) + (node_iteration_work ? ", two dispatches" : ", three");
        DeviceOptions lanes, groups;
        lanes.precision = groups.precision = precision;
        lanes.node_iteration_work = groups.node_iteration_work = node_iteration_work;
        groups.cg_sigma_lanes_from = 0;
        VulkanEnsemble by_lanes(model, estimated, scenario.observations.nodes, S, lanes);
        VulkanEnsemble by_groups(model, estimated, scenario.observations.nodes, S, groups);
        const VulkanDeviceInfo& info = by_lanes.device_info();
        ASSERT_EQ(by_lanes.cg_lane_rows(), cg_lane_rows(kCgSigmaLanesFrom, S, info, true, true)) << what;
        if (info.subgroup_shuffle && info.subgroup_size >= 8) {
          ASSERT_EQ(by_lanes.cg_lane_rows(), S == 4 ? 2 : 1) << what;
        }
        ASSERT_EQ(by_groups.cg_lane_rows(), 0) << what;
        const Eigen::MatrixXd theta = test::spread_log_stiffness(scenario, model, S, 0.3);
        by_lanes.set_parameters(theta);
        by_groups.set_parameters(theta);
        double moved = 0.0, apart = 0.0;
        const Eigen::VectorXd start = by_groups.positions(0);
        long long iterations = 0;
        for (int k = 1; k <= 40; ++k) {
          const Eigen::Vector3d so = scenario.control.trajectory.position(k * scenario.time.dt, scenario.control.start);
          const StepReport a = by_lanes.advance(so);
          const StepReport b = by_groups.advance(so);
          EXPECT_EQ(a.unconverged_count(), 0) << what;
          for (const int i : a.cg_iterations) iterations += i;
          for (int s = 0; s < S; ++s)
            EXPECT_LE(std::abs(a.cg_iterations[s] - b.cg_iterations[s]), 1) << what << ", step " << k << ", sigma point " << s;
        }
        for (int s = 0; s < S; ++s) {
          moved = std::max(moved, (by_groups.positions(s) - start).cwiseAbs().maxCoeff());
          apart = std::max(apart, (by_lanes.positions(s) - by_groups.positions(s)).cwiseAbs().maxCoeff());
        }
        EXPECT_GT(moved, 1e-4) << what << ": the steps move the nodes";
        EXPECT_GT(iterations, 40 * S) << what << ": CG iterates";
        EXPECT_LT(apart, precision == Precision::single ? 2e-7 : 1e-14) << what;
      }
    }
  }
}

// Which lanes the CG shaders take: a sigma point a lane from cg_sigma_lanes_from, J = 8 / S a
// sigma point at S <= 4 with the factor and 8-lane shuffles, else a group a sigma point; on a
// CPU device with one partition only.
TEST(VulkanCgLanes, LanesOverSigmaPointsWhereTheyFillTheVectors) {
  VulkanDeviceInfo info;
  info.type = "cpu";
  info.subgroup_shuffle = true;
  info.subgroup_size = 8;
  EXPECT_EQ(cg_lane_rows(16, 16, info, true, true), 1);
  EXPECT_EQ(cg_lane_rows(16, 65, info, true, false), 1);   // Jacobi too
  EXPECT_EQ(cg_lane_rows(16, 8, info, true, true), 0);     // one group would leave threads idle
  EXPECT_EQ(cg_lane_rows(16, 4, info, true, true), 2);
  EXPECT_EQ(cg_lane_rows(16, 3, info, true, true), 2);
  EXPECT_EQ(cg_lane_rows(16, 2, info, true, true), 4);
  EXPECT_EQ(cg_lane_rows(16, 1, info, true, true), 8);
  EXPECT_EQ(cg_lane_rows(16, 4, info, true, false), 0);    // the shuffle entries are the factor's
  EXPECT_EQ(cg_lane_rows(0, 16, info, true, true), 0);     // never
  EXPECT_EQ(cg_lane_rows(16, 16, info, false, true), 0);   // partitions
  info.subgroup_size = 4;
  EXPECT_EQ(cg_lane_rows(16, 4, info, true, true), 0);
  info.type = "discrete gpu";
  info.subgroup_size = 32;
  EXPECT_EQ(cg_lane_rows(16, 64, info, true, true), 0);
}

// The CG shaders' loop turns (cg_loop_turns): lanes walking every node of a sigma point turn
// each node's element corners and ligaments and kCgNodeTurns more; lanes taking nodes in steps
// turn as the busiest node of each step needs, so fewer the longer the step, never less than
// their share, and with one step over all the nodes the busiest node's alone; partitions as
// many shares, the busiest counting.
TEST(VulkanCgLoopTurns, CountTheBusiestLanesCornersAndLigaments) {
  const Model model = make_model(load_scenario(kScenarios + "liver.json"));
  const int nodes = model.node_count();
  std::vector<long long> node_turns(static_cast<std::size_t>(nodes), kCgNodeTurns);
  for (const ElementRest& element : model.elements)
    for (const int n : element.nodes) ++node_turns[static_cast<std::size_t>(n)];
  for (const SpringSet& ligament : model.ligaments)
    for (const int n : ligament.nodes) ++node_turns[static_cast<std::size_t>(n)];
  long long ligament_nodes = 0;
  for (const SpringSet& ligament : model.ligaments) ligament_nodes += static_cast<long long>(ligament.nodes.size());
  ASSERT_GT(ligament_nodes, 0);
  const long long all = kCgNodeTurns * nodes + 4LL * model.element_count() + ligament_nodes;
  EXPECT_EQ(cg_loop_turns(model, 1), all);
  EXPECT_EQ(cg_loop_turns(model, nodes), *std::max_element(node_turns.begin(), node_turns.end()));
  long long last = all;
  for (const int step : {2, 4, 8, 16, 32}) {
    const long long turns = cg_loop_turns(model, step);
    EXPECT_LT(turns, last) << "step " << step;
    EXPECT_GE(turns, all / step) << "step " << step;
    last = turns;
  }
  // Partitions: each walks its share of the nodes; the busiest partition counts.
  EXPECT_EQ(cg_loop_turns(model, 8, 1), cg_loop_turns(model, 8));
  EXPECT_LT(cg_loop_turns(model, 8, 2), cg_loop_turns(model, 8));
  EXPECT_GE(cg_loop_turns(model, 8, 2), cg_loop_turns(model, 8) / 2);
  EXPECT_EQ(cg_loop_turns(model, 1, nodes), *std::max_element(node_turns.begin(), node_turns.end()));
}

// Where the lanes over sigma points would turn their loops more than an invocation may
// (DeviceOptions::cg_loop_turns, made small here: lavapipe's own bound needs the 38k liver,
// below), CG takes a work-group a sigma point, grown until its lanes' share of the nodes fits,
// with the lanes' results (as CgWithASigmaPointALaneFollowsAGroupASigmaPoint).
TEST_F(VulkanDeviceTest, CgGroupsGrowToKeepWithinTheLoopTurns) {
  const Scenario scenario = load_scenario(kScenarios + "liver.json");
  const std::vector<int>& estimated = scenario.filter->estimate;
  const Model model = make_model(scenario);
  const int S = 4;
  ASSERT_LT(cg_loop_turns(model, 16), cg_loop_turns(model, 8));
  for (const Precision precision : {Precision::single, Precision::double_precision}) {
    const std::string what = precision == Precision::single ? "float" : "double";
    DeviceOptions lanes, bounded;
    lanes.precision = bounded.precision = precision;
    bounded.cg_loop_turns = cg_loop_turns(model, 8) - 1;
    VulkanEnsemble by_lanes(model, estimated, scenario.observations.nodes, S, lanes);
    VulkanEnsemble by_groups(model, estimated, scenario.observations.nodes, S, bounded);
    if (by_lanes.cg_lane_rows() == 0) GTEST_SKIP() << "this device has no lanes over sigma points at S = 4";
    ASSERT_EQ(by_groups.cg_lane_rows(), 0) << what;
    ASSERT_EQ(by_groups.cg_group_size(), 16u) << what;
    const Eigen::MatrixXd theta = test::spread_log_stiffness(scenario, model, S, 0.3);
    long iterations_lanes = 0, iterations_groups = 0;
    const Eigen::MatrixXd a = test::run_steps(by_lanes, scenario, theta, 40, iterations_lanes);
    const Eigen::MatrixXd b = test::run_steps(by_groups, scenario, theta, 40, iterations_groups);
    EXPECT_GT(iterations_lanes, 40 * S) << what << ": CG iterates";
    EXPECT_LE(std::abs(iterations_lanes - iterations_groups), 40) << what;
    EXPECT_LT((a - b).cwiseAbs().maxCoeff(), precision == Precision::single ? 2e-7 : 1e-14) << what;
  }
}

// The factor made again in the background (BackgroundMaking), forced on the liver (as
// OpenClFactorTest's): handed over at a step fixed when its making began, so two runs give the
// same bits, and the run stays within CG's tolerance of the one that waited for each making.
TEST_F(VulkanDeviceTest, AFactorMadeInTheBackgroundGivesTheSameBitsEveryRun) {
  const Scenario scenario = load_scenario(kScenarios + "liver.json");
  const Model model = make_model(scenario);
  const int S = 4;
  const Eigen::MatrixXd theta = test::spread_log_stiffness(scenario, model, S, 0.3);
  const auto run_with = [&](int lag) {
    VulkanEnsemble ensemble(model, scenario.filter->estimate, scenario.observations.nodes, S,
                            test::background_making_options(lag));
    test::MakingRun made;
    if (!ensemble.factorised()) return made;
    made.x = test::run_steps(ensemble, scenario, theta, 300, made.iterations);
    made.makings = ensemble.factorisations();
    return made;
  };
  const test::MakingRun waited = run_with(0);
  if (waited.x.size() == 0) GTEST_SKIP() << "Vulkan's factor is a CPU device's";
  test::expect_background_making_repeats(waited, run_with(3), run_with(3), 1e-6);
}

// As OpenCL's (OpenClFactorTest.AFactorMadeInTheBackgroundKeepsTheSpringsOfItsStep).
TEST_F(VulkanDeviceTest, AFactorMadeInTheBackgroundKeepsTheSpringsOfItsStep) {
  const Scenario scenario = load_scenario(kScenarios + "liver.json");
  const Model model = make_model(scenario);
  const int S = 4;
  test::expect_the_making_steps_springs(
      [&](int lag) {
        DeviceOptions options;   // the factor, corrected for the sigma points' springs, as by default
        options.preconditioner = Preconditioner::factorised;
        options.background_making_solves = 0.0;
        options.background_making_steps = lag;
        return std::make_unique<VulkanEnsemble>(model, scenario.filter->estimate, scenario.observations.nodes, S,
                                                options);
      },
      scenario, test::spread_log_stiffness(scenario, model, S, 0.3));
}

// The 38k liver's filter (S = 4, the factor): its 2 lanes a sigma point would turn the CG
// shaders' loops ~115 000 times, past lavapipe's 65535, which then ended them silently and CG
// started from a residual whose last rows were never written (the filter's estimate went
// non-finite in some runs: stop 58). It takes a group of 8 a sigma point instead, and its steps
// follow the CPU reference's. Not VulkanDeviceTest: not under the validation layer; long (14 s).
TEST(VulkanLoopTurnsTest, TheFineLiversCgFollowsTheCpuReference) {
  std::string why;
  const std::vector<VulkanDeviceInfo> devices = list_vulkan_devices(&why);
  if (devices.empty()) SIGMAFEM_MISSING(why);
  if (devices[0].type != "cpu") GTEST_SKIP() << "Vulkan's factor and llvmpipe's bound are a CPU device's";
  const Scenario scenario = test::refined_liver(2);
  const std::vector<int>& estimated = scenario.filter->estimate;
  const Model model = make_model(scenario);
  ASSERT_GT(cg_loop_turns(model, 2), 65535);
  const int S = 4, steps = 10;
  DeviceOptions options;
  options.preconditioner = Preconditioner::factorised;
  VulkanEnsemble vulkan(model, estimated, scenario.observations.nodes, S, options);
  if (vulkan.cg_lane_rows() == 0) {
    EXPECT_LE(cg_loop_turns(model, static_cast<int>(vulkan.cg_group_size())), kShaderLoopTurns);
  } else {
    EXPECT_LE(cg_loop_turns(model, vulkan.cg_lane_rows()), kShaderLoopTurns);
  }
  const std::unique_ptr<SimulationEnsemble> cpu =
      make_ensemble("cpu", model, estimated, scenario.observations.nodes, S);
  const Eigen::MatrixXd theta = test::spread_log_stiffness(scenario, model, S, 0.3);
  long iterations = 0, cpu_iterations = 0;
  const Eigen::MatrixXd x = test::run_steps(vulkan, scenario, theta, steps, iterations);
  const Eigen::MatrixXd reference = test::run_steps(*cpu, scenario, theta, steps, cpu_iterations);
  double moved = 0.0;
  for (int s = 0; s < S; ++s)
    for (int n = 0; n < model.node_count(); ++n)
      moved = std::max(moved, (reference.col(s).segment<3>(3 * n) - model.rest_positions[static_cast<std::size_t>(n)])
                                  .cwiseAbs().maxCoeff());
  // Measured: moved 4.7e-6 m, 55 iterations in all, apart 7.7e-8 m (float32 positions of
  // ~0.1 m); with the 2 lanes a sigma point 3305 iterations and apart 2e9.
  EXPECT_GT(moved, 1e-6) << "the steps move the nodes";
  EXPECT_LE(iterations, 4L * S * steps) << "the factor's CG takes a few iterations a step";
  EXPECT_LT((x - reference).cwiseAbs().maxCoeff(), 5e-7);
}

// The memory check's estimate (ensemble_memory with Vulkan's blocks) against what the ensemble
// holds on the device once its factor is made: the refined liver at S = 4 and 16 (measured
// 1.08x and 1.05x the estimate; L's entries by columns would have counted 2/3 of the blocks).
TEST_F(VulkanDeviceTest, TheMemoryCheckCountsTheFactorsBlocks) {
  const Scenario scenario = test::refined_liver(1);
  const Model model = make_model(scenario);
  for (const int S : {4, 16}) {
    DeviceOptions options;
    options.preconditioner = Preconditioner::factorised;
    VulkanEnsemble ensemble(model, scenario.filter->estimate, scenario.observations.nodes, S, options);
    ensemble.advance(scenario.control.trajectory.position(scenario.time.dt, scenario.control.start));
    ASSERT_EQ(ensemble.factorisations(), 1);
    const double estimate = static_cast<double>(
        ensemble_memory(model.node_count(), model.element_count(), S, sizeof(float),
                        ensemble.factor_nonzeros(), FactorStorage::blocks, 1, SF_FRAME_TWO_ROWS).total);
    const double held = static_cast<double>(ensemble.device_bytes());
    EXPECT_GT(held, 0.8 * estimate) << "S = " << S;
    EXPECT_LT(held, 1.25 * estimate) << "S = " << S;
  }
}

// Lavapipe's threads by the ensemble's work (DeviceOptions::lavapipe_serial_work): the box at
// S = 4 (5376 element-sigma pairs) runs its shaders on the submitting thread (LP_NUM_THREADS
// "0" while its device is made), the same box asked to take the threads gets lavapipe's default
// (a thread a core), a user's own LP_NUM_THREADS is kept; the bits are the same either way.
TEST_F(VulkanDeviceTest, SmallEnsemblesRunLavapipeSeriallyWithTheSameBits) {
  const Scenario scenario = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.json");
  const Model model = make_model(scenario);
  const std::vector<int>& estimated = scenario.filter->estimate;
  const int S = static_cast<int>(estimated.size()) + 1;
  ASSERT_LT(static_cast<long long>(model.element_count()) * S, kLavapipeSerialWork);
  const char* users = std::getenv("LP_NUM_THREADS");
  const std::string before = users ? users : "";
  const bool ours = choose_lavapipe_threads(false);
  VulkanEnsemble serial(model, estimated, scenario.observations.nodes, S, DeviceOptions{});
  const char* now = std::getenv("LP_NUM_THREADS");
  if (ours) {
    EXPECT_STREQ(now, "0");
  } else {
    EXPECT_EQ(std::string(now ? now : ""), before) << "the user's LP_NUM_THREADS is kept";
  }
  DeviceOptions threads;
  threads.lavapipe_serial_work = 0;
  VulkanEnsemble threaded(model, estimated, scenario.observations.nodes, S, threads);
  now = std::getenv("LP_NUM_THREADS");
  const unsigned cores = std::thread::hardware_concurrency();
  if (ours) {
    EXPECT_EQ(std::string(now ? now : ""), std::to_string(cores > 1 ? cores : 0));
  }
  for (int k = 1; k <= 5; ++k) {
    const Eigen::Vector3d so = scenario.control.trajectory.position(k * scenario.time.dt, scenario.control.start);
    const StepReport a = serial.advance(so);
    const StepReport b = threaded.advance(so);
    EXPECT_EQ(a.unconverged_count(), 0);
    EXPECT_EQ(a.cg_iterations, b.cg_iterations) << "step " << k;
  }
  for (int s = 0; s < S; ++s) EXPECT_TRUE(serial.positions(s) == threaded.positions(s)) << "sigma point " << s;
}

// The form of the shaders: the CPU form (texel reads) on a CPU device by default or when asked,
// when every buffer fits a texel view; else the GPU form.
TEST(VulkanTexelReads, TheCpuFormWithinTheDevicesTexelLimit) {
  const unsigned long long limit = 1ull << 27;   // lavapipe's and NVIDIA's maxTexelBufferElements
  EXPECT_TRUE(vulkan_texel_reads(KernelForm::automatic, "cpu", 1 << 20, limit));
  EXPECT_FALSE(vulkan_texel_reads(KernelForm::automatic, "discrete gpu", 1 << 20, limit));
  EXPECT_TRUE(vulkan_texel_reads(KernelForm::cpu, "discrete gpu", 1 << 20, limit));
  EXPECT_FALSE(vulkan_texel_reads(KernelForm::gpu, "cpu", 1 << 20, limit));
  // The largest buffer: 4 bytes a texel.
  EXPECT_TRUE(vulkan_texel_reads(KernelForm::automatic, "cpu", 4 * limit, limit));
  EXPECT_FALSE(vulkan_texel_reads(KernelForm::automatic, "cpu", 4 * limit + 4, limit));
}

}  // namespace
}  // namespace sigmafem
