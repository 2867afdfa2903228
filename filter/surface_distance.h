// The closest point of a triangle surface to a point in space: which triangle, where on it
// (barycentric weights) and how far. The point-cloud observation (filter/
// point_cloud_observation.h) finds where each measured point lies on the organ's deformed
// surface with it, once per filter step, for hundreds to thousands of points: the triangles
// sit in a uniform grid of cells about a triangle in size, and a query visits shells of cells
// around the point until no unvisited cell can hold a nearer triangle. Eigen's KdBVH
// (unsupported/Eigen/BVH) was tried first: with it the observation of 1000 points on the
// liver's 276 triangles took 1.33 ms, 70% of it in its best-first traversal (a priority queue
// per query), against 0.45 ms with the grid (bench/RESULTS.md, "Point clouds").
#pragma once

#include <Eigen/Core>
#include <array>
#include <limits>
#include <vector>

namespace sigmafem {

// The barycentric weights (of a, b, c; each >= 0, summing to 1) of the point of triangle abc
// nearest to p, by the Voronoi regions of its corners, edges and face (Ericson, "Real-Time
// Collision Detection", 2005, 5.1.5). A degenerate triangle (a segment or a point) gives the
// nearest of its corners.
Eigen::Vector3d closest_point_weights(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                      const Eigen::Vector3d& b, const Eigen::Vector3d& c);

struct SurfacePoint {
  int triangle = -1;                    // index into the triangles
  Eigen::Vector3d weights = Eigen::Vector3d::Zero();   // of the triangle's corners, in its order
  double distance = std::numeric_limits<double>::infinity();   // m, unsigned
};

class SurfaceSearch {
 public:
  // `positions` holds 3 numbers per vertex (x0 y0 z0 x1 ...); `triangles` index the vertices.
  // Both are copied as needed; the search answers for these positions until rebuilt.
  SurfaceSearch(const Eigen::VectorXd& positions, const std::vector<std::array<int, 3>>& triangles);

  // The point of the surface nearest to p (distance infinite and triangle -1 with no triangle).
  SurfacePoint closest(const Eigen::Vector3d& p) const;

 private:
  Eigen::Vector3d vertex(int v) const { return positions_.segment<3>(3 * static_cast<Eigen::Index>(v)); }
  // The cell index of cell (i, j, k).
  Eigen::Index cell(const Eigen::Array3i& ijk) const {
    return (static_cast<Eigen::Index>(ijk[2]) * cells_[1] + ijk[1]) * cells_[0] + ijk[0];
  }
  // The cell coordinates holding x, clamped to the grid.
  Eigen::Array3i cell_of(const Eigen::Vector3d& x) const;
  // Tests triangle t against p, keeping the nearer in `best` (squared distance in best_squared).
  void try_triangle(int t, const Eigen::Vector3d& p, SurfacePoint& best, double& best_squared) const;

  Eigen::VectorXd positions_;
  std::vector<std::array<int, 3>> triangles_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();   // the grid's lower corner
  double cell_size_ = 1.0;
  Eigen::Array3i cells_ = Eigen::Array3i::Ones();      // per axis
  std::vector<int> cell_start_;      // cells + 1: cell c holds cell_triangles_[start[c], start[c+1])
  std::vector<int> cell_triangles_;  // each triangle in every cell its bounding box overlaps
};

}  // namespace sigmafem
