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
// The rows are the surface's triangles, not the points (docs/ROUKF.md, "Point clouds"): each
// frame's points are binned by the triangle they matched, and triangle t's row is
//
//   y_s(t) = sum over its n_t points of h_s(p) / sqrt(n_t)
//
// (sqrt(n_t) times their mean distance: variance sigma^2 like one point's, so R is unchanged).
// A point's own row would be another point at every step; a triangle is the same place of the
// organ from step to step, which the adaptive noise needs (filter/adaptive_noise.h: it tells a
// persistent model error from noise by the lag-1 correlation of a row). Measured on the liver
// with an undeclared 3 mm camera offset across the view: one row per point drove a stiffness
// past 1e9 N/m at step 72; binned, the run completes (LiverCloudEstimation, stop 35).
// What the binning drops is each triangle's tilt (the spread of its points' distances across
// it; h is affine on a planar triangle, so the mean is the distance at the points' centroid),
// which its neighbours, sharing its nodes, mostly carry. A triangle no point fell on has no
// row this step (predicts_row).
// The outlier gate (filter/outlier_gate.h) works here, per point before the binning, with the
// filter's test: a point's innovation against the variance the sigma points predict for it,
// so that one outlier does not take the good points of its triangle with it.
//
// A frame may hold any number of points.
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
#include "filter/outlier_gate.h"

namespace sigmafem {

struct PointCloudOptions {
  double observation_std = 0.0;     // m, one point's noise along the normal: the gate's R
  OutlierGateOptions outlier_gate;  // per point, before the binning
};

class PointCloudObservation : public Ensemble {
 public:
  // `surface` observes the organ's surface nodes: its observation count is 3 x the nodes that
  // `triangles` index (outward-oriented, in the order of its observed points).
  PointCloudObservation(std::unique_ptr<Ensemble> surface, std::vector<std::array<int, 3>> triangles,
                        const PointCloudOptions& options = {});

  // The measured points of the coming step (3 x n; n = 0: nothing measured) and when in it
  // each was taken (n shares in (0, 1]; empty: all at the step's end).
  void set_frame(const Eigen::Matrix3Xd& points, const Eigen::VectorXd& share = {});

  int sigma_count() const override { return surface_->sigma_count(); }
  int parameter_count() const override { return surface_->parameter_count(); }
  int observation_count() const override { return static_cast<int>(triangles_.size()); }
  void set_parameters(const Eigen::MatrixXd& theta) override { surface_->set_parameters(theta); }
  StepReport advance(const Eigen::Vector3d& so_position) override;
  // triangles x S: y_s(t) for the triangles the frame's points fell on, 0 on the others.
  void predicted_observations(Eigen::MatrixXd& y) const override;
  bool predicts_row(Eigen::Index row) const override { return bin_size_[static_cast<std::size_t>(row)] > 0; }
  std::vector<int> rejected_points() const override { return rejected_; }
  void recenter(const Recentering& recentering) override;
  int rows_per_point() const override { return 1; }   // a triangle's row

 private:
  std::unique_ptr<Ensemble> surface_;
  std::vector<std::array<int, 3>> triangles_;
  PointCloudOptions options_;
  double alpha_ = 0.0;                          // the sigma points' weight and directions, for
  Eigen::MatrixXd directions_;                  // the gate's predicted variance (as in Roukf)
  Eigen::Matrix3Xd frame_;
  Eigen::VectorXd share_;                       // per point of the frame, (0, 1]
  bool between_steps_ = false;                  // a point of the frame was taken before the step's end
  Eigen::MatrixXd start_positions_;             // 3n x S, the surface at the step's start
  bool start_read_ = false;                     // start_positions_ holds the coming step's start
  mutable Eigen::MatrixXd surface_positions_;   // 3n x S, the surface's nodes (reused)
  mutable std::vector<int> bin_size_;           // per triangle, the last prediction's points
  mutable std::vector<int> rejected_;           // the frame's points the gate left out
};

}  // namespace sigmafem
