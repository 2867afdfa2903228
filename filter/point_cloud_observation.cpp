#include "filter/point_cloud_observation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "filter/surface_distance.h"

namespace sigmafem {

PointCloudObservation::PointCloudObservation(std::unique_ptr<Ensemble> surface,
                                             std::vector<std::array<int, 3>> triangles,
                                             const PointCloudOptions& options)
    : surface_(std::move(surface)), triangles_(std::move(triangles)), options_(options),
      bin_size_(triangles_.size(), 0) {
  if (!surface_) throw std::invalid_argument("PointCloudObservation: no ensemble");
  if (triangles_.empty()) throw std::invalid_argument("PointCloudObservation: no surface triangles");
  const int nodes = surface_->observation_count() / 3;
  for (const std::array<int, 3>& tri : triangles_)
    for (int v : tri)
      if (v < 0 || v >= nodes)
        throw std::invalid_argument("PointCloudObservation: a triangle uses observed node " + std::to_string(v) +
                                    " of " + std::to_string(nodes));
}

void PointCloudObservation::set_frame(const Eigen::Matrix3Xd& points, const Eigen::VectorXd& share) {
  if (share.size() != 0 && share.size() != points.cols())
    throw std::invalid_argument("PointCloudObservation: " + std::to_string(share.size()) + " times for " +
                                std::to_string(points.cols()) + " points");
  if (share.size() != 0 && !(share.array() > 0.0 && share.array() <= 1.0).all())
    throw std::invalid_argument("PointCloudObservation: a point's share of the step must lie in (0, 1]");
  frame_ = points;
  share_ = share.size() != 0 ? share : Eigen::VectorXd::Ones(points.cols());
  between_steps_ = (share_.array() < 1.0).any();
  start_read_ = false;
}

void PointCloudObservation::recenter(const Recentering& recentering) {
  alpha_ = recentering.alpha;
  directions_ = recentering.directions;
  surface_->recenter(recentering);
}

StepReport PointCloudObservation::advance(const Eigen::Vector3d& so_position) {
  // The re-sampled state the sigma points start the step from, for points taken inside it.
  start_read_ = between_steps_;
  if (start_read_) surface_->predicted_observations(start_positions_);
  return surface_->advance(so_position);
}

void PointCloudObservation::predicted_observations(Eigen::MatrixXd& y) const {
  surface_->predicted_observations(surface_positions_);   // 3n x S: the surface nodes
  const Eigen::Index S = surface_positions_.cols();
  const Eigen::Index n = frame_.cols();
  y = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(triangles_.size()), S);
  std::fill(bin_size_.begin(), bin_size_.end(), 0);
  rejected_.clear();
  if (n == 0) return;
  // Each point's h_s(p), and the triangle it matched on the sigma points' mean surface (they
  // have equal weights, both sets, filter/sigma_points.h).
  const SurfaceSearch search(surface_positions_.rowwise().mean(), triangles_);
  Eigen::MatrixXd h(n, S);
  std::vector<int> triangle_of(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d p = frame_.col(i);
    const SurfacePoint at = search.closest(p);
    triangle_of[static_cast<std::size_t>(i)] = at.triangle;
    const std::array<int, 3>& tri = triangles_[static_cast<std::size_t>(at.triangle)];
    const double u = share_[i];
    for (Eigen::Index s = 0; s < S; ++s) {
      // Corner c of sigma point s's triangle when p was taken.
      const auto corner = [&](int c) -> Eigen::Vector3d {
        const Eigen::Index row = 3 * static_cast<Eigen::Index>(tri[static_cast<std::size_t>(c)]);
        const Eigen::Vector3d end = surface_positions_.col(s).segment<3>(row);
        if (u == 1.0 || !start_read_) return end;   // on the grid, or no step made since set_frame
        const Eigen::Vector3d start = start_positions_.col(s).segment<3>(row);
        return start + u * (end - start);
      };
      const Eigen::Vector3d a = corner(0), b = corner(1), c = corner(2);
      const Eigen::Vector3d x = at.weights[0] * a + at.weights[1] * b + at.weights[2] * c;
      const Eigen::Vector3d normal = (b - a).cross(c - a).normalized();
      h(i, s) = normal.dot(x - p);
    }
  }
  // The gate, per point, with the filter's test (filter/outlier_gate.h): the innovation is 0 - h.
  if (options_.outlier_gate.enabled) {
    std::vector<int> points(static_cast<std::size_t>(n));
    for (Eigen::Index i = 0; i < n; ++i) points[static_cast<std::size_t>(i)] = static_cast<int>(i);
    rejected_ = gate_sigma_point_innovations(options_.outlier_gate, points, -h,
                                             alpha_ > 0.0 ? alpha_ : 1.0 / static_cast<double>(S), directions_,
                                             options_.observation_std * options_.observation_std, 1);
  }
  std::vector<char> rejected(static_cast<std::size_t>(n), 0);
  for (int i : rejected_) rejected[static_cast<std::size_t>(i)] = 1;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (rejected[static_cast<std::size_t>(i)]) continue;
    const int t = triangle_of[static_cast<std::size_t>(i)];
    y.row(t) += h.row(i);
    ++bin_size_[static_cast<std::size_t>(t)];
  }
  for (std::size_t t = 0; t < triangles_.size(); ++t)
    if (bin_size_[t] > 1) y.row(static_cast<Eigen::Index>(t)) /= std::sqrt(static_cast<double>(bin_size_[t]));
}

}  // namespace sigmafem
