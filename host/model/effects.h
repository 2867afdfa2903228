// The candidate effects (host/scenario/effect_catalogue.h) applied to the simulation and to
// the observations.
//   Fixed values (declared in the scenario, or injected into generated data): apply_effects()
//   changes a Model once (gravity added, Young's modulus or the damping scaled, an inclusion's
//   elements scaled, the ligament law or the SO lag set, an extra ligament appended);
//   camera_offset() is what the observations gain.
//   Per sigma point (diagnose estimates them): PhysicsEffects, which ReferenceSimulation and
//   CpuEnsemble take per simulation; an extra ligament is one more estimated ligament
//   (add_extra_ligament); the observation-side ones live in EffectEnsemble.
#pragma once

#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

#include "host/model/model.h"
#include "host/scenario/effect_catalogue.h"

namespace sigmafem {

// The physics effects of one simulation, relative to its model (identity: none).
struct PhysicsEffects {
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();   // m/s^2, added to the model's gravity
  double young_scale = 1.0;                            // multiplies every element's Lame terms
  double lambda_scale = 1.0;                           // multiplies every element's Lame lambda
  double damping_mass_scale = 1.0;                     // multiplies damping.rayleigh_mass
  double damping_stiffness_scale = 1.0;                // multiplies damping.rayleigh_stiffness
  // The ligament law's d0 (m) instead of the model's; infinite: the model's.
  double ligament_d0 = std::numeric_limits<double>::infinity();
  double time_lag = 0.0;                               // s, added to the model's so_lag
  double control_scale = 1.0;                          // multiplies the model's control_scale
};

// Changes `model` by the physics effects among `effects`; observation effects are ignored.
// Throws InputError for an extra ligament at a region the model does not have.
void apply_effects(const std::vector<EffectValue>& effects, Model& model);

// Appends the ligament of the regional effect `effect_name` (extra_ligament:REGION) to
// model.ligaments with `stiffness`, on the nodes of that candidate region; returns its index.
// Throws InputError naming the regions when the model has no such region.
int add_extra_ligament(Model& model, const std::string& effect_name, double stiffness);

// The sum of the camera_offset effects among `effects` (zero when none).
Eigen::Vector3d camera_offset(const std::vector<EffectValue>& effects);

}  // namespace sigmafem
