#include "filter/surface_distance.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace sigmafem {

Eigen::Vector3d closest_point_weights(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                      const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return {1.0, 0.0, 0.0};                       // corner a
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return {0.0, 1.0, 0.0};                        // corner b
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 && d1 - d3 > 0.0) {                // edge ab
    const double v = d1 / (d1 - d3);
    return {1.0 - v, v, 0.0};
  }
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return {0.0, 0.0, 1.0};                        // corner c
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 && d2 - d6 > 0.0) {                // edge ac
    const double w = d2 / (d2 - d6);
    return {1.0 - w, 0.0, w};
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 && (d4 - d3) + (d5 - d6) > 0.0) {   // edge bc
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {0.0, 1.0 - w, w};
  }
  const double sum = va + vb + vc;
  if (sum > 0.0) {                                                           // inside the face
    const double v = vb / sum, w = vc / sum;
    return {1.0 - v - w, v, w};
  }
  // Degenerate (zero area) and no region above claimed p: the nearest corner.
  const double da = ap.squaredNorm(), db = bp.squaredNorm(), dc = cp.squaredNorm();
  if (da <= db && da <= dc) return {1.0, 0.0, 0.0};
  return db <= dc ? Eigen::Vector3d(0.0, 1.0, 0.0) : Eigen::Vector3d(0.0, 0.0, 1.0);
}

SurfaceSearch::SurfaceSearch(const Eigen::VectorXd& positions,
                             const std::vector<std::array<int, 3>>& triangles)
    : positions_(positions), triangles_(triangles) {
  if (triangles_.empty()) return;
  // The grid: the surface's bounding box in cells of about a triangle's size (the mean
  // largest extent of a triangle's box), at most 32 cells per triangle.
  Eigen::Vector3d low = vertex(triangles_[0][0]), high = low;
  double extent_sum = 0.0;
  for (const std::array<int, 3>& tri : triangles_) {
    const Eigen::Vector3d a = vertex(tri[0]), b = vertex(tri[1]), c = vertex(tri[2]);
    const Eigen::Vector3d box_low = a.cwiseMin(b).cwiseMin(c), box_high = a.cwiseMax(b).cwiseMax(c);
    low = low.cwiseMin(box_low);
    high = high.cwiseMax(box_high);
    extent_sum += (box_high - box_low).maxCoeff();
  }
  origin_ = low;
  const Eigen::Vector3d size = high - low;
  cell_size_ = std::max(extent_sum / static_cast<double>(triangles_.size()), 1e-12 * std::max(1.0, size.maxCoeff()));
  const double max_cells = 32.0 * static_cast<double>(triangles_.size());
  for (;;) {
    for (int a = 0; a < 3; ++a) cells_[a] = std::max(1, static_cast<int>(std::ceil(size[a] / cell_size_)));
    if (static_cast<double>(cells_[0]) * cells_[1] * cells_[2] <= max_cells) break;
    cell_size_ *= 1.25;
  }
  // Counting sort of (cell, triangle) pairs into cell_start_ / cell_triangles_.
  const Eigen::Index cell_count = static_cast<Eigen::Index>(cells_[0]) * cells_[1] * cells_[2];
  cell_start_.assign(static_cast<std::size_t>(cell_count) + 1, 0);
  auto for_each_cell = [&](const std::array<int, 3>& tri, auto&& body) {
    const Eigen::Vector3d a = vertex(tri[0]), b = vertex(tri[1]), c = vertex(tri[2]);
    const Eigen::Array3i lo = cell_of(a.cwiseMin(b).cwiseMin(c)), hi = cell_of(a.cwiseMax(b).cwiseMax(c));
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) body(cell(Eigen::Array3i(i, j, k)));
  };
  for (const std::array<int, 3>& tri : triangles_)
    for_each_cell(tri, [&](Eigen::Index c) { ++cell_start_[static_cast<std::size_t>(c) + 1]; });
  for (std::size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  cell_triangles_.resize(static_cast<std::size_t>(cell_start_.back()));
  std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t t = 0; t < triangles_.size(); ++t)
    for_each_cell(triangles_[t], [&](Eigen::Index c) {
      cell_triangles_[static_cast<std::size_t>(fill[static_cast<std::size_t>(c)]++)] = static_cast<int>(t);
    });
}

Eigen::Array3i SurfaceSearch::cell_of(const Eigen::Vector3d& x) const {
  Eigen::Array3i ijk;
  for (int a = 0; a < 3; ++a) {
    const double u = std::floor((x[a] - origin_[a]) / cell_size_);
    ijk[a] = u < 0.0 ? 0 : u >= cells_[a] ? cells_[a] - 1 : static_cast<int>(u);
  }
  return ijk;
}

void SurfaceSearch::try_triangle(int t, const Eigen::Vector3d& p, SurfacePoint& best, double& best_squared) const {
  const std::array<int, 3>& tri = triangles_[static_cast<std::size_t>(t)];
  const Eigen::Vector3d a = vertex(tri[0]), b = vertex(tri[1]), c = vertex(tri[2]);
  const Eigen::Vector3d w = closest_point_weights(p, a, b, c);
  const double squared = (w[0] * a + w[1] * b + w[2] * c - p).squaredNorm();
  if (squared < best_squared) {
    best_squared = squared;
    best.triangle = t;
    best.weights = w;
  }
}

SurfacePoint SurfaceSearch::closest(const Eigen::Vector3d& p) const {
  SurfacePoint best;
  if (triangles_.empty()) return best;
  double best_squared = std::numeric_limits<double>::infinity();
  const Eigen::Array3i c = cell_of(p);
  for (int r = 0;; ++r) {
    // The shell of cells at Chebyshev distance r from c.
    const Eigen::Array3i lo = (c - r).max(0), hi = (c + r).min(cells_ - 1);
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) {
          if (std::max({std::abs(i - c[0]), std::abs(j - c[1]), std::abs(k - c[2])}) != r) continue;
          const Eigen::Index id = cell(Eigen::Array3i(i, j, k));
          for (int n = cell_start_[static_cast<std::size_t>(id)]; n < cell_start_[static_cast<std::size_t>(id) + 1]; ++n)
            try_triangle(cell_triangles_[static_cast<std::size_t>(n)], p, best, best_squared);
        }
    // A triangle in no visited cell lies beyond the visited block's faces that are not the
    // grid's own: no nearer to p than the nearest such face.
    double bound = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      if (c[a] - r > 0) bound = std::min(bound, std::max(0.0, p[a] - (origin_[a] + (c[a] - r) * cell_size_)));
      if (c[a] + r < cells_[a] - 1)
        bound = std::min(bound, std::max(0.0, origin_[a] + (c[a] + r + 1) * cell_size_ - p[a]));
    }
    if (best_squared <= bound * bound || bound == std::numeric_limits<double>::infinity()) break;
  }
  best.distance = std::sqrt(best_squared);
  return best;
}

}  // namespace sigmafem
