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
  // Every sigma point's positions and velocities, n x S each (3 per node, node-major, as the
  // CPU reference), for a re-centring done elsewhere: the distributed ensemble
  // (host/mpi/distributed_ensemble.h) re-samples the states of all ranks' sigma points at once.
  virtual void read_states(Eigen::MatrixXd& positions, Eigen::MatrixXd& velocities) const = 0;
  virtual void write_states(const Eigen::MatrixXd& positions, const Eigen::MatrixXd& velocities) = 0;
};

// write_states' check: both n x S; std::invalid_argument naming `who` otherwise.
inline void check_state_matrices(const Eigen::MatrixXd& positions, const Eigen::MatrixXd& velocities,
                                 Eigen::Index n, int S, const std::string& who) {
  if (positions.rows() != n || positions.cols() != S || velocities.rows() != n || velocities.cols() != S)
    throw std::invalid_argument(who + "::write_states: expected two " + std::to_string(n) + " x " +
                                std::to_string(S) + " matrices");
}

}  // namespace sigmafem
