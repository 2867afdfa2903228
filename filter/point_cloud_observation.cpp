#include "filter/point_cloud_observation.h"

#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>
#include <string>

#include "filter/surface_distance.h"

namespace sigmafem {

PointCloudObservation::PointCloudObservation(std::unique_ptr<Ensemble> surface,
                                             std::vector<std::array<int, 3>> triangles, int max_points)
    : surface_(std::move(surface)), triangles_(std::move(triangles)), max_points_(max_points) {
  if (!surface_) throw std::invalid_argument("PointCloudObservation: no ensemble");
  if (max_points_ < 1) throw std::invalid_argument("PointCloudObservation: max_points must be at least 1");
  if (triangles_.empty()) throw std::invalid_argument("PointCloudObservation: no surface triangles");
  const int nodes = surface_->observation_count() / 3;
  for (const std::array<int, 3>& tri : triangles_)
    for (int v : tri)
      if (v < 0 || v >= nodes)
        throw std::invalid_argument("PointCloudObservation: a triangle uses observed node " + std::to_string(v) +
                                    " of " + std::to_string(nodes));
}

void PointCloudObservation::set_frame(const Eigen::Matrix3Xd& points, const Eigen::VectorXd& share) {
  if (points.cols() > max_points_)
    throw std::invalid_argument("PointCloudObservation: a frame of " + std::to_string(points.cols()) +
                                " points, more than the " + std::to_string(max_points_) + " it was made for");
  if (share.size() != 0 && share.size() != points.cols())
    throw std::invalid_argument("PointCloudObservation: " + std::to_string(share.size()) + " times for " +
                                std::to_string(points.cols()) + " points");
  if (share.size() != 0 && !(share.array() > 0.0 && share.array() <= 1.0).all())
    throw std::invalid_argument("PointCloudObservation: a point's share of the step must lie in (0, 1]");
  frame_ = points;
  share_ = share.size() != 0 ? share : Eigen::VectorXd::Ones(points.cols());
  between_steps_ = (share_.array() < 1.0).any();
}

StepReport PointCloudObservation::advance(const Eigen::Vector3d& so_position) {
  // The re-sampled state the sigma points start the step from, for points taken inside it.
  if (between_steps_) surface_->predicted_observations(start_positions_);
  return surface_->advance(so_position);
}

void PointCloudObservation::predicted_observations(Eigen::MatrixXd& y) const {
  surface_->predicted_observations(surface_positions_);   // 3n x S: the surface nodes
  const Eigen::Index S = surface_positions_.cols();
  y = Eigen::MatrixXd::Zero(max_points_, S);
  if (frame_.cols() == 0) return;
  // The sigma points have equal weights (both sets, filter/sigma_points.h): the mean surface.
  const SurfaceSearch search(surface_positions_.rowwise().mean(), triangles_);
  for (Eigen::Index i = 0; i < frame_.cols(); ++i) {
    const Eigen::Vector3d p = frame_.col(i);
    const SurfacePoint at = search.closest(p);
    const std::array<int, 3>& tri = triangles_[static_cast<std::size_t>(at.triangle)];
    const double u = share_[i];
    for (Eigen::Index s = 0; s < S; ++s) {
      // Corner c of sigma point s's triangle when p was taken.
      const auto corner = [&](int c) -> Eigen::Vector3d {
        const Eigen::Index row = 3 * static_cast<Eigen::Index>(tri[static_cast<std::size_t>(c)]);
        const Eigen::Vector3d end = surface_positions_.col(s).segment<3>(row);
        if (u == 1.0) return end;
        const Eigen::Vector3d start = start_positions_.col(s).segment<3>(row);
        return start + u * (end - start);
      };
      const Eigen::Vector3d a = corner(0), b = corner(1), c = corner(2);
      const Eigen::Vector3d x = at.weights[0] * a + at.weights[1] * b + at.weights[2] * c;
      const Eigen::Vector3d normal = (b - a).cross(c - a).normalized();
      y(i, s) = normal.dot(x - p);
    }
  }
}

}  // namespace sigmafem
