// PointCloudObservation: a cloud of measured surface points per frame, with no identity from
// one frame to the next (a depth camera, a laser scanner; issue 15, item 2), as the filter's
// observation. It wraps the ensemble that simulates the organ and observes its surface nodes,
// and turns their positions into one number per measured point p:
//
//   h_s(p) = n_s . (x_s - p)
//
// for sigma point s, where x_s is the point of sigma point s's surface that corresponds to p
// and n_s the outward unit normal of its triangle there. The data is 0 (p lies on the organ's
// surface, up to noise), so the innovation 0 - h = n . (p - x) is the signed distance of the
// measured point from the model's surface, positive outside.
//
// The correspondence is found once per frame, on the mean of the sigma points' surfaces: the
// closest point of that surface to p (filter/surface_distance.h), a triangle and barycentric
// weights, which every sigma point then uses with its own node positions and normal. This is
// the distance to sigma point s's tangent plane at the corresponding point: the point-to-
// surface distance to first order in the sigma points' spread (the signed distance function's
// gradient is the normal), and, unlike a closest point searched on each sigma surface, smooth
// in the parameters (no sigma point jumps to another triangle), which the unscented transform's
// finite differences need.
//
// A frame may hold any number of points up to max_points: the data leaves the rows beyond its
// count out (NaN there, as for missing tracked points).
//
// Frames at their own times (a camera's clock, not the simulation's): a point taken at a
// share u of the coming step (0 at its start, 1 at its end) is observed on each sigma point's
// surface interpolated linearly in time between the step's start (the re-sampled state,
// read before the advance) and its end, so that the filter corrects at the frame's time; the
// match on the mean surface is made at the step's end.
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <vector>

#include "filter/ensemble.h"

namespace sigmafem {

class PointCloudObservation : public Ensemble {
 public:
  // `surface` observes the organ's surface nodes: its observation count is 3 x the nodes that
  // `triangles` index (outward-oriented, in the order of its observed points).
  PointCloudObservation(std::unique_ptr<Ensemble> surface, std::vector<std::array<int, 3>> triangles,
                        int max_points);

  // The measured points of the coming step (3 x n, n <= max_points; n = 0: nothing measured)
  // and when in it each was taken (n shares in (0, 1]; empty: all at the step's end).
  void set_frame(const Eigen::Matrix3Xd& points, const Eigen::VectorXd& share = {});

  int sigma_count() const override { return surface_->sigma_count(); }
  int parameter_count() const override { return surface_->parameter_count(); }
  int observation_count() const override { return max_points_; }
  void set_parameters(const Eigen::MatrixXd& theta) override { surface_->set_parameters(theta); }
  StepReport advance(const Eigen::Vector3d& so_position) override;
  // max_points x S: h_s(p) for the frame's points, 0 beyond them.
  void predicted_observations(Eigen::MatrixXd& y) const override;
  void recenter(const Recentering& recentering) override { surface_->recenter(recentering); }
  int rows_per_point() const override { return 1; }   // one distance per measured point

 private:
  std::unique_ptr<Ensemble> surface_;
  std::vector<std::array<int, 3>> triangles_;
  int max_points_;
  Eigen::Matrix3Xd frame_;
  Eigen::VectorXd share_;                       // per point of the frame, (0, 1]
  bool between_steps_ = false;                  // a point of the frame was taken before the step's end
  Eigen::MatrixXd start_positions_;             // 3n x S, the surface at the step's start
  mutable Eigen::MatrixXd surface_positions_;   // 3n x S, the surface's nodes (reused)
};

}  // namespace sigmafem
