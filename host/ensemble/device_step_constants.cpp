#include "host/ensemble/device_step_constants.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "step_constants.h"

namespace sigmafem {

StepConstants::StepConstants(const Model& model, int sigma_count, double cg_tolerance, int estimated_regions)
    : physics_(static_cast<std::size_t>(std::max(sigma_count, 0))),
      region_scales_(Eigen::MatrixXd::Ones(estimated_regions, std::max(sigma_count, 0))),
      so_history_(model.control_start, model.dt),
      cg_tolerance_(cg_tolerance) {}

void StepConstants::set_physics_effects(const std::vector<PhysicsEffects>& effects, const std::string& who) {
  if (effects.size() != physics_.size())
    throw std::invalid_argument(who + "::set_physics_effects: expected one entry per sigma point");
  physics_ = effects;
}

void StepConstants::set_region_scales(const Eigen::MatrixXd& scales) {
  if (scales.rows() != region_scales_.rows() || scales.cols() != region_scales_.cols())
    throw std::invalid_argument("StepConstants::set_region_scales: expected one row per estimated region, one column per sigma point");
  region_scales_ = scales;
}

std::size_t StepConstants::size() const {
  return SF_STEP_CONSTANTS + (SF_REGION_SCALES + 1 + static_cast<std::size_t>(region_scales_.rows())) * physics_.size();
}

std::vector<double> StepConstants::next_step(const Model& m, const Eigen::Vector3d& so_position) {
  so_history_.push(so_position);
  const double h = m.dt;
  const std::size_t S = physics_.size();
  std::vector<double> c(size());
  c[SF_H] = h;
  c[SF_CG_TOLERANCE2] = cg_tolerance_ * cg_tolerance_;
  for (std::size_t s = 0; s < S; ++s) {
    const PhysicsEffects& e = physics_[s];
    auto at = [&](int k) -> double& { return c[SF_STEP_CONSTANTS + k * S + s]; };
    const Eigen::Vector3d gravity = m.gravity + e.gravity;
    const Eigen::Vector3d shift =
        m.control_scale * e.control_scale * (so_history_.lagged(m.so_lag + e.time_lag) - m.control_start);
    const double d0 = std::isfinite(e.ligament_d0) ? e.ligament_d0 : m.ligament_d0;
    const double a = e.damping_stiffness_scale * m.damping.rayleigh_stiffness;
    const double b = e.damping_mass_scale * m.damping.rayleigh_mass;
    for (int k = 0; k < 3; ++k) {
      at(SF_GRAVITY + k) = gravity[k];
      at(SF_SO_SHIFT + k) = shift[k];
    }
    at(SF_INVERSE_D0_SQUARED) = 1.0 / (d0 * d0);   // 0 for the linear law (infinite d0)
    at(SF_YOUNG_SCALE) = e.young_scale;
    at(SF_LAMBDA_SCALE) = e.lambda_scale;
    at(SF_MASS_FACTOR) = 1.0 + h * b;
    at(SF_STIFFNESS_FACTOR) = h * (h + a);
    at(SF_RAYLEIGH_MASS) = b;
    at(SF_VELOCITY_FACTOR) = h + a;
    at(SF_REGION_SCALES) = 1.0;   // slot 0: no estimated region
    for (Eigen::Index k = 0; k < region_scales_.rows(); ++k)
      at(SF_REGION_SCALES + 1 + static_cast<int>(k)) = region_scales_(k, static_cast<Eigen::Index>(s));
  }
  return c;
}

}  // namespace sigmafem
