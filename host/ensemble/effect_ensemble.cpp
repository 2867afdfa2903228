#include "host/ensemble/effect_ensemble.h"

#include <algorithm>
#include <cmath>

#include "host/common/input_error.h"
#include "host/ensemble/cpu_ensemble.h"
#include "host/model/effects.h"

namespace sigmafem {

EffectEnsemble::EffectEnsemble(std::unique_ptr<Ensemble> inner, const std::vector<std::string>& effects)
    : inner_(std::move(inner)) {
  cpu_ = dynamic_cast<CpuEnsemble*>(inner_.get());
  for (const std::string& name : effects) {
    const EffectDefinition* definition = find_effect(name);
    if (!definition || !definition->candidate)
      throw InputError("effect " + name + ": not in the candidate library (" + effect_names(true) + ")");
    if (std::find(effects_.begin(), effects_.end(), definition) != effects_.end())
      throw InputError("effect " + name + ": listed twice");
    if (definition->side == EffectSide::physics && !cpu_)
      throw InputError("effect " + name + ": estimating a physics effect needs the cpu back end "
                       "(the device kernels take only stiffnesses for now); run with --backend cpu");
    effects_.push_back(definition);
    effect_parameter_count_ += static_cast<int>(definition->parameters.size());
  }
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
  const int p0 = inner_->parameter_count(), S = sigma_count();
  inner_->set_parameters(theta.topRows(p0));
  std::vector<PhysicsEffects> physics(static_cast<std::size_t>(S));
  camera_offsets_.setZero(3, S);
  int row = p0;
  for (const EffectDefinition* definition : effects_) {
    const int k = static_cast<int>(definition->parameters.size());
    for (int s = 0; s < S; ++s) {
      const std::vector<double> v = effect_value(*definition, theta.block(row, s, k, 1));
      if (definition->name == "gravity") physics[s].gravity = Eigen::Vector3d(v[0], v[1], v[2]);
      else if (definition->name == "young_scale") physics[s].young_scale = v[0];
      else if (definition->name == "camera_offset") camera_offsets_.col(s) = Eigen::Vector3d(v[0], v[1], v[2]);
    }
    row += k;
  }
  if (cpu_) cpu_->set_physics_effects(physics);
}

StepReport EffectEnsemble::advance(const Eigen::Vector3d& so_position) { return inner_->advance(so_position); }

void EffectEnsemble::predicted_observations(Eigen::MatrixXd& y) const {
  inner_->predicted_observations(y);
  for (Eigen::Index r = 0; r + 2 < y.rows(); r += 3) y.middleRows(r, 3) += camera_offsets_;
}

void EffectEnsemble::recenter(const Recentering& recentering) { inner_->recenter(recentering); }

}  // namespace sigmafem
