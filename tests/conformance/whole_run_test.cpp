// A whole box estimation (the cut at step 750 and 250 steps after it, 0.5 mm noise, simplex) on a device back end
// agrees with the same run on the CPU back end: every estimate at every step within 0.5%
// (issues 4 and 5), for every device back end present (OpenCL, Vulkan). The device runs in float32 with a CG tolerance of 1e-6; the filter sees the
// observed positions to about 1e-7 m (tests/conformance/ensemble_conformance_test.cpp)
// against 0.5 mm of noise, so its estimates can differ only by a small fraction of a percent.
#include <gtest/gtest.h>

#include <cmath>

#include "generated_data.h"
#include "requirement.h"
#include "tests/filter/scenario_filter_options.h"
#include "filter/estimation.h"
#include "host/ensemble/make_ensemble.h"
#include "host/model/model.h"
#include "host/opencl/opencl_device.h"
#include "host/vulkan/vulkan_device.h"
#include "host/scenario/scenario.h"

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
  Scenario s = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.json");
  // The shipped 1500 steps took 280 s on lavapipe (2-core machine); the last 500 add nothing
  // to the comparison: the cut is at step 750, and the middle ligament's estimate is down
  // from 284 to 14 N/m by step 800 and 3 N/m by step 1000 (estimates.csv of `sigmafem
  // estimate scenarios/box.json`, seed 1), the filter following the cut through its drift.
  s.time.steps = 1000;
  const ObservationTable data = test::generated_observations(s);

  const EstimationRun cpu = estimate_box(s, data, "cpu");
  const EstimationRun device = estimate_box(s, data, backend);
  ASSERT_TRUE(cpu.complete) << cpu.stop_reason;
  ASSERT_TRUE(device.complete) << device.stop_reason;
  ASSERT_EQ(cpu.steps.size(), device.steps.size());
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
