// A whole box estimation (320 steps, the cut at step 170, 0.5 mm noise, simplex) on a device back end
// agrees with the same run on the CPU back end: every estimate at every step within 0.5%
// (issues 4 and 5), for every device back end present (OpenCL, Vulkan). The device runs in float32 with a CG tolerance of 1e-6; the filter sees the
// observed positions to about 1e-7 m (tests/conformance/ensemble_conformance_test.cpp)
// against 0.5 mm of noise, so its estimates can differ only by a small fraction of a percent.
#include <gtest/gtest.h>

#include <cmath>

#include "filter/estimation.h"
#include "generated_data.h"
#include "host/engine/make_ensemble.h"
#include "host/model/model.h"
#include "host/opencl/opencl_device.h"
#include "host/scenario/scenario.h"
#include "host/vulkan/vulkan_device.h"
#include "cpu_vulkan_skips.h"
#include "requirement.h"
#include "tests/filter/scenario_filter_options.h"

namespace sigmafem {
namespace {

EstimationRun estimate_box(const Scenario& s, const ObservationTable& data,
                           const std::string& backend) {
  const EstimationOptions options =
      test::filter_options(s, SigmaPointSet::simplex, s.filter->observation_std);
  auto ensemble = make_ensemble(backend, make_model(s), s.filter->estimate, s.observations.nodes,
                                static_cast<int>(s.filter->estimate.size()) + 1);
  return run_estimation(*ensemble, options, data.times, data.so, data.points, {});
}

class WholeRun : public ::testing::TestWithParam<std::string> {};

TEST_P(WholeRun, EstimatesMatchTheCpuBackEnd) {
  const std::string backend = GetParam();
  std::string why;
  if (backend == "opencl" && list_opencl_devices().empty()) why = "no OpenCL platform on this machine";
  if (backend == "vulkan") list_vulkan_devices(&why);   // sets `why` when there is none
  if (!why.empty()) SIGMAFEM_MISSING(why);
  // 114 s on lavapipe (stop 49), the suite's longest test: the filter's host code is the
  // device ensemble's that OpenCL's case runs, and the shaders are checked step by step.
  if (backend == "vulkan")
    SIGMAFEM_SKIP_ON_CPU_VULKAN("WholeRun/OpenCl (the same DeviceEnsemble host code) and the Vulkan conformance cases (its shaders, step by step)");
  Scenario s = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.json");
  // Shorter than the shipped run (1500 steps, the cut at step 750: 280 s on lavapipe on the
  // 2-core machine, the longest test of the suite), with the same parts: the estimates
  // moving fast from twice the truth (where the back ends differed most, steps 25-36), the
  // cut, and the filter following it (since issue 16 the cut rule finds the middle ligament
  // cut and sets it next to zero; the test prints when). Until stop 39 550 steps with the
  // cut at 300, until stop 41 450 with the cut at 250 (60 s on lavapipe on a fresh machine);
  // shortened for the test command's time.
  ASSERT_EQ(s.events.size(), 1u);
  const int middle = 1;   // the cut ligament's row among the estimated ones
  ASSERT_EQ(s.ligaments[s.filter->estimate[middle]].name, s.events[0].ligament_name);
  s.events[0].time = 1.7;
  s.time.steps = 320;
  const int cut_step = static_cast<int>(std::lround(s.events[0].time / s.time.dt));   // 170
  const ObservationTable data = test::generated_observations(s);

  const EstimationRun cpu = estimate_box(s, data, "cpu");
  const EstimationRun device = estimate_box(s, data, backend);
  ASSERT_TRUE(cpu.complete) << cpu.stop_reason;
  ASSERT_TRUE(device.complete) << device.stop_reason;
  ASSERT_EQ(cpu.steps.size(), device.steps.size());
  // The comparison spans the filter following the cut: the middle ligament's estimate (the
  // CPU back end's) falls to under a tenth of its value at the cut by the last step.
  double at_cut = std::nan("");
  for (const auto& step : cpu.steps)
    if (step.step == cut_step) at_cut = step.stiffness[middle];
  const double at_end = cpu.steps.back().stiffness[middle];
  EXPECT_LT(at_end, 0.1 * at_cut) << "middle ligament at the cut and at the end (N/m)";
  std::cout << "middle ligament (CPU back end): " << at_cut << " N/m at the cut, " << at_end
            << " N/m at step " << cpu.steps.back().step << "; found cut at step "
            << (cpu.cuts.empty() ? -1 : cpu.cuts[0].step) << "\n";
  double largest = 0.0;
  int worst = 0;
  for (std::size_t k = 0; k < cpu.steps.size(); ++k) {
    const Eigen::VectorXd ratio =
        (device.steps[k].stiffness.array() / cpu.steps[k].stiffness.array() - 1.0).abs();
    if (ratio.maxCoeff() > largest) {
      largest = ratio.maxCoeff();
      worst = cpu.steps[k].step;
    }
    EXPECT_EQ(device.steps[k].unconverged_sigma_points, 0) << "step " << cpu.steps[k].step;
  }
  EXPECT_LT(largest, 0.005) << "largest relative difference at step " << worst;
  std::cout << backend << ": largest relative difference of the estimates over " << cpu.steps.size()
            << " steps: " << largest << " (step " << worst << ")\n";
}

std::string backend_name(const ::testing::TestParamInfo<std::string>& info) {
  return info.param == "opencl" ? "OpenCl" : "Vulkan";
}

INSTANTIATE_TEST_SUITE_P(Backends, WholeRun, ::testing::Values("opencl", "vulkan"), backend_name);

}  // namespace
}  // namespace sigmafem
