#include "filter/ligament_cut.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace sigmafem {

LigamentCutRule::LigamentCutRule(const LigamentCutOptions& options, int ligaments)
    : options_(options),
      cut_(static_cast<std::size_t>(std::max(ligaments, 0)), false),
      upper_bound_(cut_.size(), NAN) {
  if (!(options.fraction > 0.0 && options.fraction < 1.0))
    throw std::invalid_argument("LigamentCutRule: fraction must lie in (0, 1), got " +
                                std::to_string(options.fraction));
  if (!(options.z >= 0.0)) throw std::invalid_argument("LigamentCutRule: z must be >= 0");
  if (!(options.remaining > 0.0 && options.remaining < options.fraction))
    throw std::invalid_argument("LigamentCutRule: remaining must lie in (0, fraction)");
}

void LigamentCutRule::arm(const Eigen::VectorXd& theta, const Eigen::VectorXd& log_std) {
  const auto n = static_cast<Eigen::Index>(cut_.size());
  if (!options_.enabled || n == 0 || theta.size() < n || log_std.size() < n) return;
  reference_theta_ = theta.head(n);
  reference_lower_log_ = theta.head(n) - options_.z * log_std.head(n);
  armed_ = true;
}

std::vector<int> LigamentCutRule::update(const Eigen::VectorXd& theta, const Eigen::VectorXd& log_std) {
  std::vector<int> cut_now;
  if (!armed_) return cut_now;
  const double log_fraction = std::log(options_.fraction);
  for (std::size_t j = 0; j < cut_.size(); ++j) {
    const auto jj = static_cast<Eigen::Index>(j);
    if (cut_[j]) continue;
    const double upper_log = theta[jj] + options_.z * log_std[jj];
    if (upper_log < reference_lower_log_[jj] + log_fraction) {
      cut_[j] = true;
      upper_bound_[j] = std::exp(upper_log);
      cut_now.push_back(static_cast<int>(j));
    }
  }
  return cut_now;
}

double LigamentCutRule::stiffness_before(int j) const {
  return armed_ ? std::exp(reference_theta_[j]) : NAN;
}

}  // namespace sigmafem
