#include "host/ensemble/effect_ensemble.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "host/common/input_error.h"

namespace sigmafem {

EffectEnsemble::EffectEnsemble(std::unique_ptr<SimulationEnsemble> inner, const std::vector<std::string>& effects)
    : inner_(std::move(inner)) {
  declared_count_ = inner_->parameter_count();
  for (const std::string& name : effects) {
    const EffectDefinition* definition = find_effect(name);
    if (!definition || !definition->candidate)
      throw InputError("effect " + name + ": not in the candidate library (" + effect_names(true) + ")");
    if (std::count(effects.begin(), effects.end(), name) > 1) throw InputError("effect " + name + ": listed twice");
    effects_.push_back(definition);
    effect_parameter_count_ += static_cast<int>(definition->parameters.size());
    if (definition->side == EffectSide::ligament) --declared_count_;
  }
  if (declared_count_ < 0)
    throw std::invalid_argument("EffectEnsemble: the inner ensemble lacks the extra ligaments' parameters");
  camera_offsets_ = Eigen::MatrixXd::Zero(3, sigma_count());
}

std::vector<double> EffectEnsemble::effect_value(const EffectDefinition& definition,
                                                 const Eigen::VectorXd& coordinates) {
  std::vector<double> value;
  for (std::size_t j = 0; j < definition.parameters.size(); ++j) {
    const EffectParameter& p = definition.parameters[j];
    const double u = p.prior_mean + p.prior_std * coordinates[static_cast<Eigen::Index>(j)];
    value.push_back(p.log ? std::exp(u) : u);
  }
  return value;
}

void EffectEnsemble::effect_estimate(const EffectDefinition& definition, const Eigen::VectorXd& coordinates,
                                     const Eigen::VectorXd& coordinate_std, std::vector<double>& value,
                                     std::vector<double>& value_std) {
  value = effect_value(definition, coordinates);
  value_std.clear();
  for (std::size_t j = 0; j < definition.parameters.size(); ++j) {
    const EffectParameter& p = definition.parameters[j];
    const double u_std = p.prior_std * coordinate_std[static_cast<Eigen::Index>(j)];
    // exp(u): the median, with the first-order std exp(u) std(u), as for the stiffnesses.
    value_std.push_back(p.log ? value[j] * u_std : u_std);
  }
}

void EffectEnsemble::set_parameters(const Eigen::MatrixXd& theta) {
  const int p0 = declared_count_, S = sigma_count();
  inner_theta_.resize(inner_->parameter_count(), S);
  inner_theta_.topRows(p0) = theta.topRows(p0);
  int inner_row = p0;
  std::vector<PhysicsEffects> physics(static_cast<std::size_t>(S));
  camera_offsets_.setZero(3, S);
  int row = p0;
  for (const EffectDefinition* definition : effects_) {
    const int k = static_cast<int>(definition->parameters.size());
    for (int s = 0; s < S; ++s) {
      const std::vector<double> v = effect_value(*definition, theta.block(row, s, k, 1));
      const std::string& name = definition->name;
      if (name == "gravity") physics[s].gravity = Eigen::Vector3d(v[0], v[1], v[2]);
      else if (name == "young_scale") physics[s].young_scale = v[0];
      else if (name == "lambda_scale") physics[s].lambda_scale = v[0];
      else if (name == "damping_scale") physics[s].damping_mass_scale = v[0], physics[s].damping_stiffness_scale = v[1];
      else if (name == "ligament_law") physics[s].ligament_d0 = v[0];
      else if (name == "time_lag") physics[s].time_lag = v[0];
      else if (name == "control_scale") physics[s].control_scale = v[0];
      else if (name == "extra_ligament") inner_theta_(inner_row, s) = std::log(v[0]);
      else if (name == "camera_offset") camera_offsets_.col(s) = Eigen::Vector3d(v[0], v[1], v[2]);
    }
    if (definition->side == EffectSide::ligament) ++inner_row;
    row += k;
  }
  inner_->set_parameters(inner_theta_);
  inner_->set_physics_effects(physics);
}

StepReport EffectEnsemble::advance(const Eigen::Vector3d& so_position) { return inner_->advance(so_position); }

void EffectEnsemble::predicted_observations(Eigen::MatrixXd& y) const {
  inner_->predicted_observations(y);
  for (Eigen::Index r = 0; r + 2 < y.rows(); r += 3) y.middleRows(r, 3) += camera_offsets_;
}

void EffectEnsemble::recenter(const Recentering& recentering) { inner_->recenter(recentering); }

}  // namespace sigmafem
