#include "filter/timed_observation.h"

#include <stdexcept>
#include <string>

namespace sigmafem {

TimedObservation::TimedObservation(std::unique_ptr<Ensemble> inner, std::vector<double> share_by_row)
    : inner_(std::move(inner)), share_by_row_(std::move(share_by_row)) {
  if (!inner_) throw std::invalid_argument("TimedObservation: no ensemble");
  for (double share : share_by_row_)
    if (!(share > 0.0 && share <= 1.0))
      throw std::invalid_argument("TimedObservation: a row's share of its step must lie in (0, 1]");
}

void TimedObservation::set_row(Eigen::Index row) {
  start_read_ = false;
  if (share_by_row_.empty()) return;   // no frame times: on the grid
  if (row < 0 || row >= static_cast<Eigen::Index>(share_by_row_.size()))
    throw std::invalid_argument("TimedObservation: no row " + std::to_string(row));
  share_ = share_by_row_[static_cast<std::size_t>(row)];
}

StepReport TimedObservation::advance(const Eigen::Vector3d& so_position) {
  // The re-sampled state the sigma points start the step from, for a frame taken inside it.
  start_read_ = share_ < 1.0;
  if (start_read_) inner_->predicted_observations(start_);
  return inner_->advance(so_position);
}

void TimedObservation::predicted_observations(Eigen::MatrixXd& y) const {
  inner_->predicted_observations(y);
  if (start_read_) y = start_ + share_ * (y - start_);   // else: no step made since set_row
}

}  // namespace sigmafem
