#include "host/model/effects.h"

#include <stdexcept>

namespace sigmafem {

void apply_effects(const std::vector<EffectValue>& effects, Model& model) {
  for (const EffectValue& effect : effects) {
    const EffectDefinition* definition = find_effect(effect.name);
    if (!definition || !effect_value_problem(*definition, effect.value).empty())
      throw std::invalid_argument("apply_effects: invalid effect " + format_effect_assignment(effect));
    if (effect.name == "gravity") {
      model.gravity += Eigen::Vector3d(effect.value[0], effect.value[1], effect.value[2]);
    } else if (effect.name == "young_scale") {
      // Linear elasticity: the Lame terms, hence K_e, are proportional to E.
      model.material.young_modulus *= effect.value[0];
      for (ElementRest& element : model.elements) {
        element.vlambda *= effect.value[0];
        element.vmu *= effect.value[0];
      }
    } else if (effect.name == "inclusion") {
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

Eigen::Vector3d camera_offset(const std::vector<EffectValue>& effects) {
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();
  for (const EffectValue& effect : effects)
    if (effect.name == "camera_offset") offset += Eigen::Vector3d(effect.value[0], effect.value[1], effect.value[2]);
  return offset;
}

}  // namespace sigmafem
