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

void PointCloudObservation::set_frame(const Eigen::Matrix3Xd& points) {
  if (points.cols() > max_points_)
    throw std::invalid_argument("PointCloudObservation: a frame of " + std::to_string(points.cols()) +
                                " points, more than the " + std::to_string(max_points_) + " it was made for");
  frame_ = points;
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
    for (Eigen::Index s = 0; s < S; ++s) {
      const auto corner = [&](int c) -> Eigen::Vector3d {
        return surface_positions_.col(s).segment<3>(3 * static_cast<Eigen::Index>(tri[static_cast<std::size_t>(c)]));
      };
      const Eigen::Vector3d a = corner(0), b = corner(1), c = corner(2);
      const Eigen::Vector3d x = at.weights[0] * a + at.weights[1] * b + at.weights[2] * c;
      const Eigen::Vector3d normal = (b - a).cross(c - a).normalized();
      y(i, s) = normal.dot(x - p);
    }
  }
}

}  // namespace sigmafem
