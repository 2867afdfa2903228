#include "host/model/effects.h"

#include <stdexcept>

#include "host/common/input_error.h"

namespace sigmafem {

void apply_effects(const std::vector<EffectValue>& effects, Model& model) {
  for (const EffectValue& effect : effects) {
    const EffectDefinition* definition = find_effect(effect.name);
    if (!definition || !effect_value_problem(*definition, effect.value).empty())
      throw std::invalid_argument("apply_effects: invalid effect " + format_effect_assignment(effect));
    const std::string& family = definition->name;
    if (family == "gravity") {
      model.gravity += Eigen::Vector3d(effect.value[0], effect.value[1], effect.value[2]);
    } else if (family == "lambda_scale") {
      // Lame lambda scaled, mu kept: nu (and with it E) moves; the material record follows,
      // lambda / mu = 2 nu / (1 - 2 nu).
      const Eigen::Vector2d lame = lame_coefficients(model.material);
      const double lambda = effect.value[0] * lame[0], mu = lame[1];
      model.material.poisson_ratio = lambda / (2.0 * (lambda + mu));
      model.material.young_modulus = mu * (3.0 * lambda + 2.0 * mu) / (lambda + mu);
      for (ElementRest& element : model.elements) element.vlambda *= effect.value[0];
    } else if (family == "young_scale") {
      // Linear elasticity: the Lame terms, hence K_e, are proportional to E.
      model.material.young_modulus *= effect.value[0];
      for (ElementRest& element : model.elements) {
        element.vlambda *= effect.value[0];
        element.vmu *= effect.value[0];
      }
    } else if (family == "damping_scale") {
      model.damping.rayleigh_mass *= effect.value[0];
      model.damping.rayleigh_stiffness *= effect.value[1];
    } else if (family == "ligament_law") {
      model.ligament_d0 = effect.value[0];
    } else if (family == "time_lag") {
      model.so_lag += effect.value[0];
    } else if (family == "control_scale") {
      model.control_scale *= effect.value[0];
    } else if (family == "extra_ligament") {
      add_extra_ligament(model, effect.name, effect.value[0]);
    } else if (family == "inclusion") {
      const Eigen::Vector3d centre(effect.value[0], effect.value[1], effect.value[2]);
      for (ElementRest& element : model.elements) {
        Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
        for (int node : element.nodes) centroid += 0.25 * model.rest_positions[node];
        if ((centroid - centre).norm() <= effect.value[3]) {
          element.vlambda *= effect.value[4];
          element.vmu *= effect.value[4];
        }
      }
    }
  }
}

int add_extra_ligament(Model& model, const std::string& effect_name, double stiffness) {
  const std::string region = effect_region(effect_name);
  std::string names;
  for (const SpringSet& candidate : model.candidate_regions) {
    if (candidate.name == region) {
      model.ligaments.push_back({effect_name, candidate.nodes, stiffness, candidate.shares});
      return static_cast<int>(model.ligaments.size()) - 1;
    }
    names += (names.empty() ? "" : ", ") + candidate.name;
  }
  throw InputError("effect " + effect_name + ": no candidate region \"" + region + "\" (candidate_regions: " +
                   (names.empty() ? "none declared" : names) + ")");
}

Eigen::Vector3d camera_offset(const std::vector<EffectValue>& effects) {
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  for (const EffectValue& effect : effects)
    if (effect.name == "camera_offset") offset += Eigen::Vector3d(effect.value[0], effect.value[1], effect.value[2]);
  return offset;
}

}  // namespace sigmafem
