// TimedObservation: tracked points measured at their frame's own time, not at the step's end
// (issue 15, item 3). A tracker's frames come at its own rate, with jitter; each is given to
// the simulation step it falls in (observations.csv's `frame_time` column, docs/FORMATS.md),
// and this decorator observes the sigma points as they were at the frame's time: for a frame
// taken at a share u of the coming step (0 at its start, 1 at its end), the observed positions
// are interpolated linearly between the step's start (the re-sampled state, read before the
// advance) and its end,
//
//   y_s(u) = y_s(start) + u (y_s(end) - y_s(start)),
//
// so that the filter corrects at the frame's time, to first order in dt, as the point-cloud
// observation does for clouds (filter/point_cloud_observation.h; measured there: frames given
// to the nearest step instead cost 12 times the error of frames on the grid).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "filter/ensemble.h"

namespace sigmafem {

class TimedObservation : public Ensemble {
 public:
  // `share_by_row`: for each data row, when in its step the row's points were taken, in
  // (0, 1] (1: at the step's end, on the grid); empty: every row on the grid (the data have no
  // frame times, and the decorator changes nothing).
  TimedObservation(std::unique_ptr<Ensemble> inner, std::vector<double> share_by_row);

  // The data row of the coming step (run_estimation's before_step).
  void set_row(Eigen::Index row);

  int sigma_count() const override { return inner_->sigma_count(); }
  int parameter_count() const override { return inner_->parameter_count(); }
  int observation_count() const override { return inner_->observation_count(); }
  void set_parameters(const Eigen::MatrixXd& theta) override { inner_->set_parameters(theta); }
  StepReport advance(const Eigen::Vector3d& so_position) override;
  void predicted_observations(Eigen::MatrixXd& y) const override;
  int rows_per_point() const override { return inner_->rows_per_point(); }
  bool predicts_row(Eigen::Index row) const override { return inner_->predicts_row(row); }
  std::vector<int> rejected_points() const override { return inner_->rejected_points(); }
  void recenter(const Recentering& recentering) override { inner_->recenter(recentering); }

 private:
  std::unique_ptr<Ensemble> inner_;
  std::vector<double> share_by_row_;
  double share_ = 1.0;                 // of the coming step
  Eigen::MatrixXd start_;              // the observations at the step's start (share < 1)
  bool start_read_ = false;            // start_ holds the coming step's start
};

}  // namespace sigmafem
