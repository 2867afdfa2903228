// EffectEnsemble: candidate effects as extra sigma-point dimensions, on every back end. An
// extra ligament is one more estimated ligament of the inner ensemble; a camera offset moves
// the predicted observations; the physics effects are per-sigma constants of the device
// kernels' step, which must give what the CPU reference gives.
#include "host/ensemble/effect_ensemble.h"

#include <gtest/gtest.h>

#include <cmath>

#include "host/common/device_error.h"
#include "host/common/input_error.h"
#include "host/engine/make_ensemble.h"
#include "host/ensemble/cpu_ensemble.h"
#include "host/model/effects.h"
#include "host/opencl/opencl_device.h"
#include "host/scenario/scenario.h"
#include "host/vulkan/vulkan_device.h"
#include "requirement.h"

namespace sigmafem {
namespace {

class EffectEnsembleTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scenario_ = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box_diagnose.json");
    model_ = make_model(scenario_);
    // Rows: the 3 declared ligaments' log-stiffness, extra_ligament:bottom's coordinate, the
    // camera offset's three; a different value per sigma point.
    theta_.resize(7, kSigma);
    for (int s = 0; s < kSigma; ++s) {
      for (int j = 0; j < 3; ++j)
        theta_(j, s) = std::log(model_.ligaments[static_cast<std::size_t>(j)].stiffness) + 0.3 * std::sin(s + j);
      theta_(3, s) = 0.5 * std::cos(s);
      for (int j = 0; j < 3; ++j) theta_(4 + j, s) = 0.2 * (s - j);
    }
  }
  Eigen::Vector3d so(int step) const {
    return scenario_.control.trajectory.position(step * scenario_.time.dt, scenario_.control.start);
  }
  static constexpr int kSigma = 3;
  const std::vector<std::string> effects_ = {"extra_ligament:bottom", "camera_offset"};
  Scenario scenario_;
  Model model_;
  Eigen::MatrixXd theta_;
};

TEST_F(EffectEnsembleTest, AnExtraLigamentIsOneMoreEstimatedLigament) {
  auto ensemble = make_effect_ensemble("cpu", model_, scenario_.filter->estimate, scenario_.observations.nodes,
                                       kSigma, {}, effects_);
  ASSERT_EQ(ensemble->parameter_count(), 7);
  ensemble->set_parameters(theta_);
  // By hand: the model with the ligament appended, its log-stiffness prior_mean + prior_std c.
  Model model = model_;
  std::vector<int> estimated = scenario_.filter->estimate;
  estimated.push_back(add_extra_ligament(model, "extra_ligament:bottom", 0.0));
  CpuEnsemble by_hand(model, estimated, scenario_.observations.nodes, kSigma);
  const EffectParameter& k = find_effect("extra_ligament:bottom")->parameters[0];
  Eigen::MatrixXd inner(4, kSigma);
  inner.topRows(3) = theta_.topRows(3);
  inner.row(3) = (k.prior_mean + k.prior_std * theta_.row(3).array()).matrix();
  by_hand.set_parameters(inner);
  for (int n = 1; n <= 20; ++n) {
    ensemble->advance(so(n));
    by_hand.advance(so(n));
  }
  Eigen::MatrixXd y, y_by_hand;
  ensemble->predicted_observations(y);
  by_hand.predicted_observations(y_by_hand);
  for (int s = 0; s < kSigma; ++s)
    for (Eigen::Index r = 0; r < y.rows(); ++r) {
      const EffectParameter& t = find_effect("camera_offset")->parameters[static_cast<std::size_t>(r % 3)];
      const double offset = t.prior_mean + t.prior_std * theta_(4 + r % 3, s);
      EXPECT_EQ(y(r, s), y_by_hand(r, s) + offset) << "row " << r << " sigma point " << s;
    }
}

// On each device back end in float64, against the CPU reference.
class EffectEnsembleOnDevice : public EffectEnsembleTest, public ::testing::WithParamInterface<std::string> {};

TEST_P(EffectEnsembleOnDevice, AnExtraLigamentAndACameraOffsetRunAsOnTheCpu) {
  if (GetParam() == "opencl") {
    const auto devices = list_opencl_devices();
    if (devices.empty()) SIGMAFEM_MISSING("no OpenCL platform on this machine");
    if (!devices[0].has_fp64) SIGMAFEM_MISSING("OpenCL device 0 has no fp64");
  } else {
    std::string why;
    const auto devices = list_vulkan_devices(&why);
    if (devices.empty()) SIGMAFEM_MISSING(why);
    if (!devices[0].has_fp64) SIGMAFEM_MISSING("Vulkan device 0 has no shaderFloat64");
  }
  DeviceOptions options;
  options.precision = Precision::double_precision;
  auto cpu = make_effect_ensemble("cpu", model_, scenario_.filter->estimate, scenario_.observations.nodes, kSigma,
                                  {}, effects_);
  auto opencl = make_effect_ensemble(GetParam(), model_, scenario_.filter->estimate, scenario_.observations.nodes,
                                     kSigma, options, effects_);
  cpu->set_parameters(theta_);
  opencl->set_parameters(theta_);
  Eigen::MatrixXd y_cpu, y_opencl;
  for (int n = 1; n <= 50; ++n) {
    cpu->advance(so(n));
    opencl->advance(so(n));
  }
  // A re-sampling with the filter's 7 parameters, more than the inner ensemble's 4.
  Recentering r;
  r.alpha = 1.0 / kSigma;
  r.directions = Eigen::MatrixXd::Zero(7, kSigma);
  for (int j = 0; j < 7; ++j) r.directions(j, j % kSigma) = 1.0, r.directions(j, (j + 1) % kSigma) = -1.0;
  r.correction = Eigen::VectorXd::LinSpaced(7, -0.2, 0.3);
  r.factor = Eigen::MatrixXd::Identity(7, 7) * 0.5;
  cpu->recenter(r);
  opencl->recenter(r);
  for (int n = 51; n <= 60; ++n) {
    cpu->advance(so(n));
    opencl->advance(so(n));
  }
  cpu->predicted_observations(y_cpu);
  opencl->predicted_observations(y_opencl);
  // float64 kernels against the float64 reference: the conformance suite's trajectory
  // tolerance (1e-9 m).
  EXPECT_LT((y_cpu - y_opencl).lpNorm<Eigen::Infinity>(), 1e-9);
  EXPECT_GT((y_cpu.col(0) - y_cpu.col(1)).norm(), 1e-6) << "the sigma points differ (the test would be empty)";
}

TEST_P(EffectEnsembleOnDevice, EveryPhysicsEffectPerSigmaPointRunsAsOnTheCpu) {
  if (GetParam() == "opencl" ? list_opencl_devices().empty() : list_vulkan_devices().empty())
    SIGMAFEM_MISSING(GetParam() << ": no device");
  // The per-sigma constants of the device kernels (step_constants.h), on a model that
  // declares a lag, a law and a control scale of its own (the per-sigma values are relative to them), each
  // sigma point with its own values.
  Model model = model_;
  apply_effects({{"time_lag", {0.02}}, {"ligament_law", {0.02}}, {"control_scale", {1.1}}, {"lambda_scale", {2.0}}},
                model);
  const std::vector<std::string> effects = {"gravity", "young_scale", "time_lag", "ligament_law", "damping_scale",
                                            "control_scale", "lambda_scale"};
  constexpr int kEffectParameters = 3 + 1 + 1 + 1 + 2 + 1 + 1;
  Eigen::MatrixXd theta(3 + kEffectParameters, kSigma);
  for (int s = 0; s < kSigma; ++s) {
    for (int j = 0; j < 3; ++j) theta(j, s) = std::log(model.ligaments[static_cast<std::size_t>(j)].stiffness);
    for (int j = 0; j < kEffectParameters; ++j) theta(3 + j, s) = 0.8 * std::sin(1.0 + 2.0 * s + j);
  }
  DeviceOptions options;
  options.precision = Precision::double_precision;
  auto cpu = make_effect_ensemble("cpu", model, scenario_.filter->estimate, scenario_.observations.nodes, kSigma, {},
                                  effects);
  std::unique_ptr<EffectEnsemble> device;
  try {
    device = make_effect_ensemble(GetParam(), model, scenario_.filter->estimate, scenario_.observations.nodes,
                                  kSigma, options, effects);
  } catch (const DeviceError& e) {
    SIGMAFEM_MISSING(e.what());
  }
  cpu->set_parameters(theta);
  device->set_parameters(theta);
  Eigen::MatrixXd y_cpu, y_device;
  for (int n = 1; n <= 60; ++n) {
    cpu->advance(so(n));
    device->advance(so(n));
  }
  cpu->predicted_observations(y_cpu);
  device->predicted_observations(y_device);
  EXPECT_LT((y_cpu - y_device).lpNorm<Eigen::Infinity>(), 1e-9);
  EXPECT_GT((y_cpu.col(0) - y_cpu.col(1)).norm(), 1e-4) << "the sigma points differ (the test would be empty)";
}

INSTANTIATE_TEST_SUITE_P(Backends, EffectEnsembleOnDevice, ::testing::Values("opencl", "vulkan"));

}  // namespace
}  // namespace sigmafem
