// The library of candidate effects (issue 6): physical or observational effects that real
// data may hold and a declared model may lack. Each is a name, the numbers that set it (its
// value, in SI units) and, for the candidates `sigmafem diagnose` tries, the parameters the
// ensemble estimates as extra sigma-point dimensions, each with its transform (log for a
// positive quantity, identity otherwise) and prior.
//
// An effect value appears in three places, always with the syntax of `value_syntax`:
//   scenario  "effects": [{"name": "camera_offset", "value": [0.5e-3, 0, 0]}]  part of the model
//   generate  --inject camera_offset=0.5e-3,0,0    in the data only, recorded in truth.json
//   diagnose  report.json and the scenario it writes with the discovered effect declared
// This file is only the catalogue and the parsing; host/model/effects.h applies them.
#pragma once

#include <string>
#include <vector>

namespace sigmafem {

// Where an effect acts:
//   physics      in the simulated physics, set per simulation (PhysicsEffects);
//   ligament     an extra spring set, estimated as one more ligament;
//   observation  in the observation operator.
enum class EffectSide { physics, ligament, observation };

// One estimated parameter. In the filter its coordinate is (u - prior_mean) / prior_std with
// u = log(value) (log) or value (identity), so that every effect coordinate has prior N(0, 1).
struct EffectParameter {
  std::string name;       // e.g. "gx"
  std::string unit;       // e.g. "m/s^2"
  bool log = false;       // log transform (positive quantity)
  double prior_mean = 0.0;  // of u
  double prior_std = 1.0;   // of u
  // The value at which the effect is absent: 0 for an added quantity, 1 for a factor,
  // infinity for a length beyond which a law is linear (diagnose tests a claim against it).
  double absent = 0.0;
};

struct EffectDefinition {
  std::string name;
  std::string description;                 // one line, for reports and --help
  EffectSide side = EffectSide::physics;
  // In `diagnose`'s candidate library. False for effects that can be injected into data but
  // that the library does not hold (the out-of-library test's stiff inclusion).
  bool candidate = true;
  bool regional = false;                   // placed at a region: named FAMILY:REGION
  std::string value_syntax;                // e.g. "gx,gy,gz (m/s^2)"
  int value_count = 0;                     // numbers in a value
  // Candidates: the estimated parameters, one per number of the value, same order.
  std::vector<EffectParameter> parameters;
};

// An effect with its value (natural units), as declared, injected or discovered. The name is
// the effect's, or for a family placed at a region, FAMILY:REGION (extra_ligament:left, the
// region one of the scenario's candidate_regions).
struct EffectValue {
  std::string name;
  std::vector<double> value;
};

// The effect part of a name ("extra_ligament" of "extra_ligament:left") and the region part
// ("left"; "" when there is none).
std::string effect_family(const std::string& name);
std::string effect_region(const std::string& name);

// Every effect this build knows, candidates first.
const std::vector<EffectDefinition>& effect_catalogue();
// The effect called `name` (FAMILY:REGION: the family's), or nullptr.
const EffectDefinition* find_effect(const std::string& name);
// "gravity, young_scale, ...": the names, for messages.
std::string effect_names(bool candidates_only = false);

// "" if `value` is a valid value of the effect `definition`, else what is wrong.
std::string effect_value_problem(const EffectDefinition& definition, const std::vector<double>& value);

// Parses NAME=V1,V2,... (the --inject syntax). Throws InputError naming `option` and what is
// wrong: an unknown name (with the known ones), a missing '=', a field that is not a number,
// the wrong count, a value out of range.
EffectValue parse_effect_assignment(const std::string& text, const std::string& option);

// "camera_offset=0.0005,0,0": the inverse of parse_effect_assignment.
std::string format_effect_assignment(const EffectValue& effect);

}  // namespace sigmafem
