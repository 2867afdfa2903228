// Issue 19's stiffness per spring of a spring set (filter.estimate_springs): the liver's middle
// ligament (nodes 18, 128, 129) estimated as three springs, with the left and right ligaments
// whole, from the 73 anterior surface nodes of liver_inclusion.json, noise-free, 1000 steps.
// Springs of one ligament a centimetre apart are weakly told apart by surface motion: their
// sum is pinned down first and the split converges slowly (measured: within 1.3% of a
// 50/100/150 N/m truth after 1000 steps, 11% off an even 100/100/100 one, the sum within 2.5%
// on both), so the test asks the sum within 3%, each spring of an uneven truth within 10% (which
// orders them) and of an even one within 15%.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <string>

#include "generated_data.h"
#include "filter/estimation.h"
#include "host/engine/estimation_options.h"
#include "host/engine/make_ensemble.h"
#include "host/model/estimated_parameters.h"
#include "host/model/model.h"
#include "host/scenario/scenario.h"

namespace sigmafem {
namespace {

Scenario load(const std::string& name) {
  return load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/" + name + ".json");
}

// liver.json without its cut, observed on the anterior nodes; the middle ligament's springs
// as given (N/m, nodes 18, 128, 129).
Scenario truth_scenario(const std::array<double, 3>& springs) {
  Scenario s = load("liver");
  s.events.clear();
  s.time.steps = 1000;
  s.observations = load("liver_inclusion").observations;
  const Ligament middle = s.ligaments[1];
  s.ligaments.erase(s.ligaments.begin() + 1);
  for (std::size_t k = 0; k < 3; ++k)
    s.ligaments.push_back({"middle_" + std::to_string(k), {middle.nodes[k]}, springs[k]});
  s.filter.reset();
  return s;
}

// The same liver, the filter estimating left and right whole and middle per spring.
Scenario estimation_scenario() {
  Scenario s = load("liver");
  s.events.clear();
  s.time.steps = 1000;
  s.observations = load("liver_inclusion").observations;
  s.filter->estimate = {0, 2};
  s.filter->initial_stiffness = {300.0, 400.0};
  s.filter->estimate_springs = {1};
  s.filter->initial_spring_stiffness = {200.0};
  s.filter->parameter_drift_log_std = 0.0;
  s.filter->observation_std = 1e-4;
  return s;
}

void expect_springs(const std::array<double, 3>& truth, double tolerance) {
  const Scenario s = estimation_scenario();
  const ObservationTable data = test::generated_observations(truth_scenario(truth));
  Model model = make_model(s);
  const EstimatedParameters estimated = estimated_parameters(*s.filter, model);
  ASSERT_EQ(estimated.count(), 5);
  EXPECT_EQ(model.ligaments[1].stiffness, 0.0) << "the whole middle ligament gives way to its springs";
  auto ensemble = make_ensemble("cpu", model, estimated, s.observations.observed, estimated.count() + 1);
  const EstimationRun run = run_estimation(*ensemble, estimation_options(s), data.times, data.so, data.points, {});
  ASSERT_TRUE(run.complete) << run.stop_reason;
  const Eigen::VectorXd& last = run.steps.back().stiffness;
  const std::vector<std::string> names = s.parameter_names();
  ASSERT_EQ(names[2], "middle@18");
  double sum = 0.0;
  for (int k = 0; k < 3; ++k) {
    std::cout << names[static_cast<std::size_t>(2 + k)] << " " << last[2 + k] << " N/m (truth " << truth[static_cast<std::size_t>(k)] << ")\n";
    EXPECT_LT(std::abs(last[2 + k] / truth[static_cast<std::size_t>(k)] - 1.0), tolerance) << names[static_cast<std::size_t>(2 + k)];
    sum += last[2 + k];
  }
  EXPECT_LT(std::abs(sum / (truth[0] + truth[1] + truth[2]) - 1.0), 0.03) << "the ligament's total";
  EXPECT_LT(std::abs(last[0] / 150.0 - 1.0), 0.05) << "left";
  EXPECT_LT(std::abs(last[1] / 200.0 - 1.0), 0.05) << "right";
}

TEST(SpringFieldEstimation, AnUnevenLigamentIsResolvedSpringBySpring) {
  expect_springs({50.0, 100.0, 150.0}, 0.10);
}

TEST(SpringFieldEstimation, AnEvenLigamentsSumIsFoundItsSplitRoughly) {
  expect_springs({100.0, 100.0, 100.0}, 0.15);
}

}  // namespace
}  // namespace sigmafem
