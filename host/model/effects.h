// The candidate effects (host/scenario/effect_catalogue.h) applied to the simulation and to
// the observations.
//   Fixed values (declared in the scenario, or injected into generated data): apply_effects()
//   changes a Model once (gravity added, Young's modulus scaled, an inclusion's elements
//   scaled); camera_offset() is what the observations gain.
//   Per sigma point (diagnose estimates them): PhysicsEffects, which ReferenceSimulation and
//   CpuEnsemble take per simulation; the observation-side ones live in EffectEnsemble.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "host/model/model.h"
#include "host/scenario/effect_catalogue.h"

namespace sigmafem {

// The physics effects of one simulation, relative to its model (identity: none).
struct PhysicsEffects {
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();   // m/s^2, added to the model's gravity
  double young_scale = 1.0;                            // multiplies every element's Lame terms
};

// Changes `model` by the physics effects among `effects`; observation effects are ignored.
void apply_effects(const std::vector<EffectValue>& effects, Model& model);

// The sum of the camera_offset effects among `effects` (zero when none).
Eigen::Vector3d camera_offset(const std::vector<EffectValue>& effects);

}  // namespace sigmafem
