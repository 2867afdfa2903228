// SurfaceCloudSampler: what a depth camera sees of the truth, for `generate` on a scenario
// with observations.surface_cloud (host/scenario/scenario.h): per frame, points spread
// uniformly by area over the visible patch of the organ's deformed surface, drawn afresh each
// frame, so that no point of one frame is a point of the next. The patch is chosen once, at
// rest: the surface triangles that face the camera and lie in the `coverage` share of the
// organ's depth nearest to it. Noise, dropouts and outliers are generate's to add.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <random>
#include <vector>

#include "host/mesh/mesh.h"
#include "host/scenario/scenario.h"

namespace sigmafem {

class SurfaceCloudSampler {
 public:
  // `mesh`: the truth's mesh at rest (its own surface: the truth may be finer than the model).
  // Throws InputError when no triangle is visible (a view direction along which nothing of the
  // surface faces the camera cannot happen for a closed surface, but a coverage too small
  // for the mesh's triangles can).
  SurfaceCloudSampler(const Mesh& mesh, const SurfaceCloud& spec, std::uint64_t seed);

  // The points_per_frame points of one frame of the organ at `positions` (3 per node).
  Eigen::Matrix3Xd sample(const Eigen::VectorXd& positions);

  const std::vector<std::array<int, 3>>& visible_triangles() const { return visible_; }
  double visible_area_at_rest() const { return visible_area_; }

 private:
  double uniform();   // in [0, 1), the same on every standard library

  std::vector<std::array<int, 3>> visible_;   // mesh node indices, outward
  double visible_area_ = 0.0;                 // m^2 at rest
  int count_;
  std::mt19937_64 engine_;
  std::vector<double> cumulative_area_;       // reused per frame
};

}  // namespace sigmafem
