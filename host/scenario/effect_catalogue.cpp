#include "host/scenario/effect_catalogue.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "host/common/input_error.h"
#include "host/common/physical_limits.h"

namespace sigmafem {

const std::vector<EffectDefinition>& effect_catalogue() {
  // Priors: wide enough to hold the effects a real set-up has at full size (issue 13: a
  // patient in any orientation, |g| = 9.81 m/s^2 in any direction, is at most 2 std on its
  // largest axis; camera registration errors up to 5 mm, 1 std per axis; tracking latencies
  // up to 0.15 s, 1.1 std; a modulus off by a factor of up to ~3), narrow enough that the
  // first sigma points stay physical.
  static const std::vector<EffectDefinition> catalogue = {
      {"gravity", "gravity the model lacks (a vector: the patient may lie in any orientation)",
       EffectSide::physics, true, false, "gx,gy,gz (m/s^2, added to the scenario's gravity)", 3,
       {{"gx", "m/s^2", false, 0.0, 5.0}, {"gy", "m/s^2", false, 0.0, 5.0}, {"gz", "m/s^2", false, 0.0, 5.0}}},
      {"young_scale", "a global scale of Young's modulus", EffectSide::physics, true, false,
       "s (> 0, multiplies material.young_modulus)", 1, {{"scale", "", true, 0.0, 0.5, 1.0}}},
      // The material's resistance to volume change: Lame lambda scaled, the shear modulus kept
      // (nu off: lambda / mu = 2 nu / (1 - 2 nu), 9 at nu = 0.45, 49 at 0.49); 1 a priori,
      // within a factor of e^1.5 (1 std): from nu = 0.45 that is 0.36 to 0.49.
      {"lambda_scale", "a scale of Lame's lambda, the shear modulus kept (Poisson's ratio off: nearer 0.5 or farther)",
       EffectSide::physics, true, false, "s (> 0, multiplies Lame lambda; no effect where nu = 0)", 1,
       {{"scale", "", true, 0.0, 1.5, 1.0}}},
      {"camera_offset", "a rigid translation of the observation frame (camera registration error)",
       EffectSide::observation, true, false, "tx,ty,tz (m, added to every observed position)", 3,
       {{"tx", "m", false, 0.0, 5e-3}, {"ty", "m", false, 0.0, 5e-3}, {"tz", "m", false, 0.0, 5e-3}}},
      // A ligament law that stiffens with stretch, d0 shared by the ligaments; d0 = 1 cm a
      // priori, within a factor of e (1 std).
      {"ligament_law", "a nonlinear ligament law: force = k d (1 + (d/d0)^2), d the node's displacement",
       EffectSide::physics, true, false, "d0 (m, > 0, shared by every ligament)", 1,
       {{"d0", "m", true, std::log(0.01), 1.0, HUGE_VAL}}},
      // A ligament the scenario does not declare, at one of its candidate_regions; 100 N/m a
      // priori, within a factor of e^1.5 (1 std): from barely there to as stiff as the others.
      {"extra_ligament", "an unmodelled ligament at one of the scenario's candidate_regions",
       EffectSide::ligament, true, true, "k (N/m, >= 0; named extra_ligament:REGION)", 1,
       {{"k", "N/m", true, std::log(100.0), 1.5}}},
      // The tracker's latency: the organ seen at t is the one driven by the SO up to t - tau.
      // 50 ms a priori, within a factor of e.
      {"time_lag", "the observations lag the SO positions by tau (the tracker's latency)",
       EffectSide::physics, true, false, "tau (s, >= 0)", 1, {{"tau", "s", true, std::log(0.05), 1.0}}},
      // Factors on the two Rayleigh coefficients (a zero coefficient stays zero); 1 a priori,
      // within a factor of e.
      {"damping_scale", "a mismatch of the Rayleigh damping: factors on its mass and stiffness coefficients",
       EffectSide::physics, true, false, "am,ak (> 0, multiply damping.rayleigh_mass and damping.rayleigh_stiffness)", 2,
       {{"am", "", true, 0.0, 1.0, 1.0}, {"ak", "", true, 0.0, 1.0, 1.0}}},
      // The SO's recorded displacement is off by a factor: a tracker's or a test rig's scale
      // calibration (for the Truth Cube, the plates' travel against the nominal strain). 1 a
      // priori, within 20% (1 std).
      {"control_scale", "the SO's displacement from its start is off by a factor (a scale calibration of the SO's record)",
       EffectSide::physics, true, false, "c (> 0, multiplies so(t) - so(0))", 1, {{"c", "", true, 0.0, 0.2, 1.0}}},
      {"inclusion", "a stiffer (or softer) sphere inside the organ: outside the candidate library",
       EffectSide::physics, false, false, "x,y,z,radius,factor (m, m, > 0: multiplies Young's modulus of the elements whose centroid is inside)",
       5, {}},
  };
  return catalogue;
}

std::string effect_family(const std::string& name) { return name.substr(0, name.find(':')); }

std::string effect_region(const std::string& name) {
  const std::size_t colon = name.find(':');
  return colon == std::string::npos ? "" : name.substr(colon + 1);
}

const EffectDefinition* find_effect(const std::string& name) {
  const std::string family = effect_family(name);
  for (const EffectDefinition& definition : effect_catalogue())
    if (definition.name == family && definition.regional == !effect_region(name).empty()) return &definition;
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
    if (!std::isfinite(x) || std::fabs(x) > kMaxScenarioMagnitude)
      return "every number must be finite and within +-1e12 (SI units)";
  if ((definition.name == "young_scale" || definition.name == "lambda_scale" || definition.name == "ligament_law" ||
       definition.name == "damping_scale" ||
       definition.name == "control_scale") &&
      !(*std::min_element(value.begin(), value.end()) > 0.0))
    return "must be > 0 (" + definition.value_syntax + ")";
  if ((definition.name == "time_lag" || definition.name == "extra_ligament") && !(value[0] >= 0.0))
    return "must be >= 0 (" + definition.value_syntax + ")";
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
    throw InputError(where + "unknown effect \"" + effect.name + "\" (known: " + effect_names() +
                     "; extra_ligament is named extra_ligament:REGION)");
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
