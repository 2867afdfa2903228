// The physics of the candidate effects (host/model/effects.h) in the CPU reference, against
// what each one means: the ligament law's force is k u (1 + |u|^2/d0^2); a time lag of whole
// steps is the same motion that many steps later; a control scale is the SO's displacement
// scaled; a per-simulation effect
// (set_physics_effects) is the same simulation as a model built with that effect; an extra
// ligament is one more ligament on its region's nodes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "host/common/input_error.h"
#include "host/model/effects.h"
#include "host/model/model.h"
#include "host/reference/reference_simulation.h"
#include "host/scenario/scenario.h"

namespace sigmafem {
namespace {

class PhysicsEffectsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scenario_ = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box_diagnose.json");
    model_ = make_model(scenario_);
  }
  Eigen::Vector3d so(int step) const {
    return scenario_.control.trajectory.position(step * scenario_.time.dt, scenario_.control.start);
  }
  Scenario scenario_;
  Model model_;
};

TEST_F(PhysicsEffectsTest, TheLigamentLawIsKuTimesOnePlusTheSquaredStretch) {
  Model model = model_;
  model.gravity.setZero();
  model.control.nodes.clear();
  model.elements.clear();   // springs only: f is the ligaments' force alone
  apply_effects({{"ligament_law", {0.004}}}, model);
  EXPECT_EQ(model.ligament_d0, 0.004);
  ReferenceSimulation simulation(model);
  Eigen::VectorXd x = simulation.positions();
  const SpringSet& ligament = model.ligaments[1];
  const int node = ligament.nodes[0];
  const Eigen::Vector3d u(0.003, -0.002, 0.001);
  x.segment<3>(3 * node) += u;
  const Eigen::VectorXd f = simulation.forces(x, {}, so(0));
  const double k = ligament.stiffness / static_cast<double>(ligament.nodes.size());
  const Eigen::Vector3d expected = -k * (1.0 + u.squaredNorm() / (0.004 * 0.004)) * u;
  EXPECT_LT((f.segment<3>(3 * node) - expected).norm(), 1e-12 * expected.norm()) << f.segment<3>(3 * node).transpose();
  // Far from d0 the law is linear: at |u| = d0 / 1000 the factor is 1 + 1e-6.
  x = simulation.positions();
  x.segment<3>(3 * node) += 1e-3 * 0.004 * u.normalized();
  const Eigen::VectorXd small = simulation.forces(x, {}, so(0));
  EXPECT_NEAR(small.segment<3>(3 * node).norm(), k * 4e-6, k * 4e-6 * 2e-6);
}

TEST_F(PhysicsEffectsTest, ATimeLagOfWholeStepsIsTheSameMotionThatManyStepsLater) {
  // Without gravity the organ is at rest until the SO moves (at t = 0), so the organ lagged
  // by 5 steps is, at step n + 5, the organ at step n, and at rest before.
  constexpr int kLagSteps = 5;
  Model model = model_;
  model.gravity.setZero();
  ReferenceSimulation now(model);
  Model lagged_model = model;
  apply_effects({{"time_lag", {kLagSteps * model_.dt}}}, lagged_model);
  ReferenceSimulation lagged(lagged_model);
  std::vector<Eigen::VectorXd> positions;
  for (int n = 1; n <= 40; ++n) {
    now.step(so(n));
    positions.push_back(now.positions());
  }
  for (int n = 1; n <= 40; ++n) {
    lagged.step(so(n));
    const Eigen::VectorXd expected =
        n > kLagSteps ? positions[static_cast<std::size_t>(n - kLagSteps - 1)] : ReferenceSimulation(model).positions();
    EXPECT_LT((lagged.positions() - expected).lpNorm<Eigen::Infinity>(), 1e-12) << "step " << n;
  }
}

// A lambda scale s is the material with lambda s times as large and the same shear modulus:
// the model made from the scenario with that Poisson's ratio and Young's modulus (nu = 0.45,
// s = 49 / 9 gives nu = 0.49).
TEST_F(PhysicsEffectsTest, ALambdaScaleIsTheMaterialWithPoissonsRatioNearerAHalf) {
  ASSERT_EQ(scenario_.material.poisson_ratio, 0.45);
  Model scaled = model_;
  apply_effects({{"lambda_scale", {49.0 / 9.0}}}, scaled);
  EXPECT_NEAR(scaled.material.poisson_ratio, 0.49, 1e-15);
  Scenario nearly_incompressible = scenario_;
  nearly_incompressible.material.poisson_ratio = 0.49;
  nearly_incompressible.material.young_modulus = scaled.material.young_modulus;
  const Model expected = make_model(nearly_incompressible);
  ASSERT_EQ(expected.elements.size(), scaled.elements.size());
  for (std::size_t e = 0; e < expected.elements.size(); ++e) {
    EXPECT_NEAR(scaled.elements[e].vlambda, expected.elements[e].vlambda, 1e-12 * expected.elements[e].vlambda);
    EXPECT_NEAR(scaled.elements[e].vmu, model_.elements[e].vmu, 0.0) << "the shear modulus is kept";
    EXPECT_NEAR(expected.elements[e].vmu, model_.elements[e].vmu, 1e-12 * model_.elements[e].vmu);
  }
}

// A control scale c is the SO's record off by c: the model driven by so(0) + c (so(t) - so(0)).
TEST_F(PhysicsEffectsTest, AControlScaleIsTheSosDisplacementScaled) {
  constexpr double c = 1.25;
  Model scaled_model = model_;
  apply_effects({{"control_scale", {c}}}, scaled_model);
  EXPECT_EQ(scaled_model.control_scale, c);
  ReferenceSimulation scaled(scaled_model), driven(model_);
  const Eigen::Vector3d start = model_.control_start;
  for (int n = 1; n <= 40; ++n) {
    scaled.step(so(n));
    driven.step(start + c * (so(n) - start));
  }
  EXPECT_LT((scaled.positions() - driven.positions()).lpNorm<Eigen::Infinity>(), 1e-12);
  EXPECT_GT((scaled.positions() - ReferenceSimulation(model_).positions()).norm(), 1e-4) << "the organ moved";
}

TEST_F(PhysicsEffectsTest, PerSimulationEffectsEqualAModelBuiltWithThem) {
  const std::vector<EffectValue> effects = {{"damping_scale", {0.5, 2.0}}, {"ligament_law", {0.006}},
                                            {"time_lag", {0.034}}, {"gravity", {0.0, 1.0, -0.5}},
                                            {"young_scale", {1.3}}, {"control_scale", {0.8}},
                                            {"lambda_scale", {3.0}}};
  Model built = model_;
  apply_effects(effects, built);
  EXPECT_EQ(built.damping.rayleigh_mass, 0.5 * model_.damping.rayleigh_mass);
  EXPECT_EQ(built.damping.rayleigh_stiffness, 2.0 * model_.damping.rayleigh_stiffness);
  ReferenceSimulation expected(built);
  ReferenceSimulation per_simulation(model_);
  PhysicsEffects physics;
  physics.damping_mass_scale = 0.5;
  physics.damping_stiffness_scale = 2.0;
  physics.ligament_d0 = 0.006;
  physics.time_lag = 0.034;
  physics.gravity = Eigen::Vector3d(0.0, 1.0, -0.5);
  physics.young_scale = 1.3;
  physics.control_scale = 0.8;
  physics.lambda_scale = 3.0;
  per_simulation.set_physics_effects(physics);
  for (int n = 1; n <= 30; ++n) {
    expected.step(so(n));
    per_simulation.step(so(n));
  }
  EXPECT_LT((expected.positions() - per_simulation.positions()).lpNorm<Eigen::Infinity>(), 1e-13);
  // And PhysicsEffects{} restores the model.
  ReferenceSimulation plain(model_), restored(model_);
  restored.set_physics_effects(physics);
  restored.set_physics_effects(PhysicsEffects{});
  for (int n = 1; n <= 10; ++n) {
    plain.step(so(n));
    restored.step(so(n));
  }
  EXPECT_EQ(plain.positions(), restored.positions());
}

TEST_F(PhysicsEffectsTest, AnExtraLigamentIsOneMoreLigamentOnItsRegion) {
  Model model = model_;
  const int index = add_extra_ligament(model, "extra_ligament:bottom", 120.0);
  ASSERT_EQ(index, static_cast<int>(model_.ligaments.size()));
  EXPECT_EQ(model.ligaments.back().name, "extra_ligament:bottom");
  EXPECT_EQ(model.ligaments.back().nodes, scenario_.candidate_regions[0].nodes);
  EXPECT_EQ(model.ligaments.back().stiffness, 120.0);
  try {
    add_extra_ligament(model, "extra_ligament:top", 1.0);
    ADD_FAILURE() << "a region the scenario lacks was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("candidate_regions: bottom, side_y0, side_y15"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace sigmafem
