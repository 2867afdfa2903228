// Issue 19's stiff inclusion (scenarios/liver_inclusion.json): Young's modulus 5x the tissue's
// in one of 8 candidate regions of the liver, which the filter is not told; from noise-free
// data it estimates the 8 moduli and the 3 ligaments (p = 11). Its figures: the inclusion's
// region is the stiffest estimate, its modulus within 15% of the truth, every other region's
// within 10%. Shown on the shipped case, with the inclusion moved to another region (data the
// scenario was not written for), and on the OpenCL back end (the device kernels' region
// scales in a whole filter run). 150 steps: the estimates are within 1% after 50 (measured on
// the 1000-step run, README "Stiffness fields").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <string>

#include "generated_data.h"
#include "requirement.h"
#include "filter/estimation.h"
#include "host/engine/estimation_options.h"
#include "host/engine/make_ensemble.h"
#include "host/model/estimated_parameters.h"
#include "host/model/model.h"
#include "host/opencl/opencl_device.h"
#include "host/scenario/scenario.h"

namespace sigmafem {
namespace {

constexpr int kSteps = 150;
constexpr double kInclusionTolerance = 0.15;   // issue 19
constexpr double kOtherTolerance = 0.10;

// The shipped scenario, shortened, with the inclusion in region `inclusion`.
Scenario inclusion_scenario(const std::string& inclusion) {
  Scenario s = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/liver_inclusion.json");
  s.time.steps = kSteps;
  const double inclusion_modulus = 5.0 * s.material.young_modulus;
  for (Region& region : s.regions)
    region.young_modulus = region.name == inclusion ? inclusion_modulus : s.material.young_modulus;
  return s;
}

void expect_inclusion_found(const std::string& backend, const std::string& inclusion) {
  const Scenario s = inclusion_scenario(inclusion);
  const ObservationTable data = test::generated_observations(s);
  const EstimationOptions options = estimation_options(s);
  Model model = make_model(s);
  const EstimatedParameters estimated = estimated_parameters(*s.filter, model);
  auto ensemble = make_ensemble(backend, model, estimated, s.observations.observed,
                                sigma_point_count(options.roukf.sigma_points, estimated.count()));
  const EstimationRun run = run_estimation(*ensemble, options, data.times, data.so, data.points, {});
  ASSERT_TRUE(run.complete) << run.stop_reason;
  const Eigen::VectorXd& last = run.steps.back().stiffness;
  const std::vector<std::string> names = s.parameter_names();
  int stiffest = -1;
  for (std::size_t k = 0; k < s.filter->estimate_regions.size(); ++k) {
    const int row = estimated.region_row(k);
    const Region& region = s.regions[static_cast<std::size_t>(s.filter->estimate_regions[k])];
    const double error = last[row] / region.young_modulus - 1.0;
    std::cout << backend << ", inclusion in " << inclusion << ": " << names[static_cast<std::size_t>(row)] << " "
              << last[row] << " Pa (truth " << region.young_modulus << ", " << 100.0 * error << "%)\n";
    EXPECT_LT(std::abs(error), region.name == inclusion ? kInclusionTolerance : kOtherTolerance) << region.name;
    if (stiffest < 0 || last[row] > last[stiffest]) stiffest = row;
  }
  EXPECT_EQ(names[static_cast<std::size_t>(stiffest)], young_modulus_parameter_name(inclusion));
  for (std::size_t j = 0; j < s.filter->estimate.size(); ++j) {
    const double truth = s.ligaments[static_cast<std::size_t>(s.filter->estimate[j])].stiffness;
    EXPECT_LT(std::abs(last[static_cast<Eigen::Index>(j)] / truth - 1.0), kOtherTolerance) << names[j];
  }
}

TEST(InclusionEstimation, TheShippedInclusionIsFound) { expect_inclusion_found("cpu", "left_upper_anterior"); }

TEST(InclusionEstimation, AnInclusionElsewhereIsFound) { expect_inclusion_found("cpu", "right_lower_posterior"); }

TEST(InclusionEstimation, TheOpenClBackEndFindsIt) {
  if (list_opencl_devices().empty()) SIGMAFEM_MISSING("no OpenCL platform on this machine");
  expect_inclusion_found("opencl", "left_upper_anterior");
}

}  // namespace
}  // namespace sigmafem
