#include "host/scenario/effect_catalogue.h"

#include <cmath>
#include <cstdlib>
#include <sstream>

#include "host/common/input_error.h"

namespace sigmafem {

const std::vector<EffectDefinition>& effect_catalogue() {
  // Priors: wide enough to hold the effects a real set-up has (a patient in any orientation:
  // |g| up to 9.81 m/s^2; a registration error of millimetres; a modulus off by a factor of
  // up to ~3), narrow enough that the first sigma points stay physical.
  static const std::vector<EffectDefinition> catalogue = {
      {"gravity", "gravity the model lacks (a vector: the patient may lie in any orientation)",
       EffectSide::physics, true, "gx,gy,gz (m/s^2, added to the scenario's gravity)", 3,
       {{"gx", "m/s^2", false, 0.0, 2.0}, {"gy", "m/s^2", false, 0.0, 2.0}, {"gz", "m/s^2", false, 0.0, 2.0}}},
      {"young_scale", "a global scale of Young's modulus", EffectSide::physics, true,
       "s (> 0, multiplies material.young_modulus)", 1, {{"scale", "", true, 0.0, 0.5}}},
      {"camera_offset", "a rigid translation of the observation frame (camera registration error)",
       EffectSide::observation, true, "tx,ty,tz (m, added to every observed position)", 3,
       {{"tx", "m", false, 0.0, 5e-3}, {"ty", "m", false, 0.0, 5e-3}, {"tz", "m", false, 0.0, 5e-3}}},
      {"inclusion", "a stiffer (or softer) sphere inside the organ: outside the candidate library",
       EffectSide::physics, false, "x,y,z,radius,factor (m, m, > 0: multiplies Young's modulus of the elements whose centroid is inside)",
       5, {}},
  };
  return catalogue;
}

const EffectDefinition* find_effect(const std::string& name) {
  for (const EffectDefinition& definition : effect_catalogue())
    if (definition.name == name) return &definition;
  return nullptr;
}

std::string effect_names(bool candidates_only) {
  std::string names;
  for (const EffectDefinition& definition : effect_catalogue())
    if (definition.candidate || !candidates_only) names += (names.empty() ? "" : ", ") + definition.name;
  return names;
}

std::string effect_value_problem(const EffectDefinition& definition, const std::vector<double>& value) {
  if (static_cast<int>(value.size()) != definition.value_count)
    return "expects " + std::to_string(definition.value_count) + " number" +
           (definition.value_count == 1 ? "" : "s") + " (" + definition.value_syntax + "), found " +
           std::to_string(value.size());
  for (double x : value)
    if (!std::isfinite(x)) return "every number must be finite";
  if (definition.name == "young_scale" && !(value[0] > 0.0))
    return "the scale must be > 0 (" + definition.value_syntax + ")";
  if (definition.name == "inclusion" && !(value[3] > 0.0 && value[4] > 0.0))
    return "radius and factor must be > 0 (" + definition.value_syntax + ")";
  return "";
}

EffectValue parse_effect_assignment(const std::string& text, const std::string& option) {
  const std::string where = option + " " + text + ": ";
  const std::size_t equals = text.find('=');
  if (equals == std::string::npos)
    throw InputError(where + "expected NAME=VALUE, e.g. camera_offset=0.5e-3,0,0 (effects: " +
                     effect_names() + ")");
  EffectValue effect;
  effect.name = text.substr(0, equals);
  const EffectDefinition* definition = find_effect(effect.name);
  if (!definition)
    throw InputError(where + "unknown effect \"" + effect.name + "\" (known: " + effect_names() + ")");
  std::stringstream fields(text.substr(equals + 1));
  std::string field;
  while (std::getline(fields, field, ',')) {
    const char* begin = field.c_str();
    char* end = nullptr;
    const double x = std::strtod(begin, &end);
    while (end && *end == ' ') ++end;
    if (field.empty() || end == begin || *end != '\0')
      throw InputError(where + "\"" + field + "\" is not a number; " + effect.name + " takes " +
                       definition->value_syntax);
    effect.value.push_back(x);
  }
  const std::string problem = effect_value_problem(*definition, effect.value);
  if (!problem.empty()) throw InputError(where + effect.name + " " + problem);
  return effect;
}

std::string format_effect_assignment(const EffectValue& effect) {
  std::ostringstream out;
  out.precision(6);
  out << effect.name << '=';
  for (std::size_t j = 0; j < effect.value.size(); ++j) out << (j ? "," : "") << effect.value[j];
  return out.str();
}

}  // namespace sigmafem
