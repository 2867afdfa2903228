// DeviceEnsemble: an Ensemble whose state can be looked into, one sigma point at a time, so
// that one conformance suite (tests/conformance/) checks every back end against the CPU
// reference step by step: the rotations, the system product, one solve, whole trajectories.
// These read-outs copy device memory to the host; the filter never calls them.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "filter/ensemble.h"
#include "host/model/effects.h"

namespace sigmafem {

class DeviceEnsemble : public Ensemble {
 public:
  // Sigma point s's positions and velocities, 3 per node (node-major, as the CPU reference).
  virtual Eigen::VectorXd positions(int s) const = 0;
  virtual Eigen::VectorXd velocities(int s) const = 0;
  // Sigma point s's element frames at the start of the last advance(), 9 per element.
  virtual std::vector<double> frames(int s) const = 0;
  // Column s of the result is A_s d_s, with A_s the implicit Euler matrix of sigma point s
  // at the last advance() (its frames and springs). d: 3N x S.
  virtual Eigen::MatrixXd system_product(const Eigen::MatrixXd& d) = 0;
  // The CG tolerance the back end solves to (float32 back ends raise the scenario's).
  virtual double cg_tolerance() const = 0;
  // "opencl single on <device>", for messages and reports.
  virtual std::string description() const = 0;

  // Per sigma point s, physics effects on top of the model (diagnose's candidates; one entry
  // per sigma point), kept until changed: per-sigma constants of each step
  // (kernels/shared/step_constants.h).
  virtual void set_physics_effects(const std::vector<PhysicsEffects>& effects) = 0;
};

}  // namespace sigmafem
