// StepConstants: the numbers of each step of a device ensemble (kernels/shared/step_constants.h,
// SF_STEP_CONSTANTS + SF_SIGMA_CONSTANT_COUNT S of them): the shared ones, then per sigma
// point s its gravity, SO target shift, the ligament law's 1/d0^2, Young's modulus scale and
// damping factors, from the model and the sigma point's physics effects (identity until set),
// then per region slot the scale of its elements' Lame terms (SF_REGION_SCALES).
// Keeps the SO history the lags need. Written once per step into DeviceBuffer::constants.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "host/model/effects.h"
#include "host/model/model.h"
#include "host/model/so_history.h"

namespace sigmafem {

class StepConstants {
 public:
  // model: so(0), dt; `estimated_regions`: the region slots after slot 0 (1 until set).
  StepConstants(const Model& model, int sigma_count, double cg_tolerance, int estimated_regions = 0);
  // One entry per sigma point (DeviceEnsemble::set_physics_effects); `who` names the caller
  // in the error for a wrong count.
  void set_physics_effects(const std::vector<PhysicsEffects>& effects, const std::string& who);
  // The constants of the next step of `model` (the one given at construction), whose SO is at
  // `so_position` at its end.
  // Estimated region k's scale for sigma point s: scales(k, s) (estimated regions x S).
  void set_region_scales(const Eigen::MatrixXd& scales);
  std::vector<double> next_step(const Model& model, const Eigen::Vector3d& so_position);
  std::size_t size() const;

 private:
  std::vector<PhysicsEffects> physics_;
  Eigen::MatrixXd region_scales_;   // estimated regions x S
  SoHistory so_history_;
  double cg_tolerance_;
};

}  // namespace sigmafem
