#include "host/generator/surface_cloud_sampler.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "host/common/input_error.h"
#include "host/data/csv_format.h"

namespace sigmafem {

SurfaceCloudSampler::SurfaceCloudSampler(const Mesh& mesh, const SurfaceCloud& spec, std::uint64_t seed)
    : count_(spec.points_per_frame), engine_(seed) {
  const Eigen::Vector3d view = spec.view_direction.normalized();
  double near = std::numeric_limits<double>::infinity(), far = -near;
  for (const Eigen::Vector3d& x : mesh.nodes) {
    near = std::min(near, view.dot(x));
    far = std::max(far, view.dot(x));
  }
  const double depth_limit = near + spec.coverage * (far - near);
  for (const std::array<int, 3>& face : boundary_faces(mesh)) {
    const Eigen::Vector3d a = mesh.nodes[static_cast<std::size_t>(face[0])];
    const Eigen::Vector3d b = mesh.nodes[static_cast<std::size_t>(face[1])];
    const Eigen::Vector3d c = mesh.nodes[static_cast<std::size_t>(face[2])];
    const Eigen::Vector3d area_normal = 0.5 * (b - a).cross(c - a);
    if (area_normal.dot(view) < 0.0 && view.dot((a + b + c) / 3.0) <= depth_limit) {
      visible_.push_back(face);
      visible_area_ += area_normal.norm();
    }
  }
  if (visible_.empty())
    throw InputError("observations.surface_cloud: no surface triangle faces the camera within coverage " +
                     format_number(spec.coverage) + " of the organ's depth; raise the coverage");
  cumulative_area_.resize(visible_.size());
}

double SurfaceCloudSampler::uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

Eigen::Matrix3Xd SurfaceCloudSampler::sample(const Eigen::VectorXd& positions) {
  auto node = [&](int n) -> Eigen::Vector3d { return positions.segment<3>(3 * static_cast<Eigen::Index>(n)); };
  double total = 0.0;
  for (std::size_t t = 0; t < visible_.size(); ++t) {
    const std::array<int, 3>& f = visible_[t];
    total += 0.5 * (node(f[1]) - node(f[0])).cross(node(f[2]) - node(f[0])).norm();
    cumulative_area_[t] = total;
  }
  Eigen::Matrix3Xd points(3, count_);
  for (int i = 0; i < count_; ++i) {
    // A triangle with probability proportional to its area, then a uniform point on it
    // (the square root makes the density uniform over the triangle, not over its heights).
    const double pick = uniform() * total;
    const auto t = static_cast<std::size_t>(
        std::min<std::ptrdiff_t>(std::upper_bound(cumulative_area_.begin(), cumulative_area_.end(), pick) -
                                     cumulative_area_.begin(),
                                 static_cast<std::ptrdiff_t>(visible_.size()) - 1));
    const double s = std::sqrt(uniform()), r = uniform();
    const std::array<int, 3>& f = visible_[t];
    points.col(i) = (1.0 - s) * node(f[0]) + s * (1.0 - r) * node(f[1]) + s * r * node(f[2]);
  }
  return points;
}

}  // namespace sigmafem
