// Young's modulus per region in the CPU reference (issue 19): a simulation given a region's
// modulus (set_region_young_modulus) is the same simulation, bit for bit, as one whose model
// was made with that modulus, with or without a young_scale effect on top; the model's own
// moduli change nothing.
#include <gtest/gtest.h>

#include "host/model/effects.h"
#include "host/model/model.h"
#include "host/reference/reference_simulation.h"
#include "host/scenario/scenario.h"

namespace sigmafem {
namespace {

Scenario with_region(double modulus) {
  Scenario scenario = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.json");
  Region region;
  region.name = "half";
  for (int e = 0; e < scenario.mesh.tetrahedron_count(); e += 2) region.elements.push_back(e);
  region.young_modulus = modulus;
  scenario.regions.push_back(region);
  return scenario;
}

Eigen::VectorXd positions_after(ReferenceSimulation& simulation, const Scenario& scenario, int steps) {
  for (int k = 1; k <= steps; ++k)
    simulation.step(scenario.control.trajectory.position(k * scenario.time.dt, scenario.control.start));
  return simulation.positions();
}

TEST(RegionModulusTest, AModulusGivenIsTheModelMadeWithIt) {
  const Scenario model_scenario = with_region(5000.0), stiff = with_region(20000.0);
  ReferenceSimulation given(make_model(model_scenario)), made(make_model(stiff)), unchanged(make_model(model_scenario));
  given.set_region_young_modulus({20000.0});
  for (std::size_t e = 0; e < given.model().elements.size(); ++e) {
    EXPECT_EQ(given.model().elements[e].vlambda, made.model().elements[e].vlambda) << e;
    EXPECT_EQ(given.model().elements[e].vmu, made.model().elements[e].vmu) << e;
  }
  const Eigen::VectorXd x_given = positions_after(given, model_scenario, 20);
  EXPECT_EQ(x_given, positions_after(made, stiff, 20));
  unchanged.set_region_young_modulus({5000.0});
  const Eigen::VectorXd x_model = positions_after(unchanged, model_scenario, 20);
  EXPECT_GT((x_given - x_model).cwiseAbs().maxCoeff(), 1e-6) << "the region's modulus moves the box";
  EXPECT_THROW(unchanged.set_region_young_modulus({1.0, 2.0}), std::invalid_argument);
}

TEST(RegionModulusTest, AYoungScaleEffectMultipliesTheRegionsModulusToo) {
  const Scenario scenario = with_region(5000.0);
  ReferenceSimulation simulation(make_model(scenario));
  simulation.set_region_young_modulus({20000.0});
  PhysicsEffects effects;
  effects.young_scale = 2.0;
  simulation.set_physics_effects(effects);
  const Model base = make_model(scenario);
  EXPECT_DOUBLE_EQ(simulation.model().elements[0].vmu, 2.0 * 4.0 * base.elements[0].vmu) << "in the region";
  EXPECT_DOUBLE_EQ(simulation.model().elements[1].vmu, 2.0 * base.elements[1].vmu) << "outside it";
}

}  // namespace
}  // namespace sigmafem
