#include "filter/parameter_drift.h"

#include <cmath>

namespace sigmafem {

ParameterDrift::ParameterDrift(const ParameterChangeTestOptions& options, Eigen::Index parameters)
    : options_(options),
      changed_at_(static_cast<std::size_t>(parameters), -1e300),
      fresh_change_at_(static_cast<std::size_t>(parameters), -1e300),
      fresh_jump_(static_cast<std::size_t>(parameters), 0.0) {}

std::vector<bool> ParameterDrift::followed_up(double k) const {
  std::vector<bool> follow_up(fresh_change_at_.size());
  for (std::size_t j = 0; j < follow_up.size(); ++j)
    follow_up[j] = k - fresh_change_at_[j] < std::log(100.0) * options_.drift_decay_steps;
  return follow_up;
}

bool ParameterDrift::goes_on(const ParameterChange& change) const {
  if (!change.follow_up) return true;
  for (Eigen::Index j = 0; j < change.jump.size(); ++j)
    if (change.jump[j] * fresh_jump_[static_cast<std::size_t>(j)] < 0.0) return false;
  return true;
}

void ParameterDrift::record(double k, const Eigen::VectorXd& jump, const ParameterChange& change) {
  for (Eigen::Index j = 0; j < jump.size(); ++j) {
    if (jump[j] == 0.0) continue;
    const auto i = static_cast<std::size_t>(j);
    changed_at_[i] = k;
    if (change.follow_up) continue;
    fresh_change_at_[i] = k;
    fresh_jump_[i] = jump[j];
  }
}

Eigen::VectorXd ParameterDrift::variance(double k) const {
  const double q = options_.drift_log_std, tau = options_.drift_decay_steps;
  Eigen::VectorXd drift(static_cast<Eigen::Index>(changed_at_.size()));
  for (std::size_t j = 0; j < changed_at_.size(); ++j)
    drift[static_cast<Eigen::Index>(j)] = q * q * std::exp(-2.0 * (k - changed_at_[j]) / tau);
  return drift;
}

}  // namespace sigmafem
