// SimulationEnsemble: an Ensemble whose sigma points are simulations of the organ, one
// interface that every back end implements (CpuEnsemble, the DeviceEnsembles), so that the
// physics effects of diagnose's candidates reach any of them without knowing which it is
// (EffectEnsemble). The filter sees only the Ensemble above it.
#pragma once

#include <vector>

#include "filter/ensemble.h"
#include "host/model/effects.h"

namespace sigmafem {

class SimulationEnsemble : public Ensemble {
 public:
  // Per sigma point s, physics effects on top of the model (one entry per sigma point), kept
  // until changed. Device back ends take them as per-sigma step constants
  // (kernels/shared/step_constants.h).
  virtual void set_physics_effects(const std::vector<PhysicsEffects>& effects) = 0;
};

}  // namespace sigmafem
