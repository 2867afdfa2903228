#include "host/model/so_history.h"

namespace sigmafem {

SoHistory::SoHistory(const Eigen::Vector3d& start, double dt) : positions_{start}, dt_(dt) {}

void SoHistory::push(const Eigen::Vector3d& so_position) { positions_.push_back(so_position); }

Eigen::Vector3d SoHistory::lagged(double lag) const {
  if (lag == 0.0) return positions_.back();
  const double at = static_cast<double>(positions_.size() - 1) - lag / dt_;
  if (at <= 0.0) return positions_.front();
  const std::size_t i = static_cast<std::size_t>(at);
  const double a = at - static_cast<double>(i);
  if (i + 1 >= positions_.size()) return positions_[i];
  return (1.0 - a) * positions_[i] + a * positions_[i + 1];
}

}  // namespace sigmafem
