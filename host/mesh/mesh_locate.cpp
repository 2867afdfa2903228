#include "host/mesh/mesh_locate.h"

#include <Eigen/Dense>
#include <algorithm>
#include <limits>
#include <stdexcept>

namespace sigmafem {

namespace {

// Barycentric weights of p in tetrahedron e: p = sum w_k node_k, sum w_k = 1.
std::array<double, 4> barycentric(const Mesh& mesh, int e, const Eigen::Vector3d& p) {
  const std::array<int, 4>& t = mesh.tetrahedra[static_cast<std::size_t>(e)];
  const Eigen::Vector3d& a = mesh.nodes[static_cast<std::size_t>(t[0])];
  Eigen::Matrix3d edges;
  for (int k = 0; k < 3; ++k) edges.col(k) = mesh.nodes[static_cast<std::size_t>(t[k + 1])] - a;
  const Eigen::Vector3d l = edges.partialPivLu().solve(p - a);
  return {1.0 - l.sum(), l[0], l[1], l[2]};
}

// Weights within kLocateTolerance of 0 become 0, negative ones too (the point is taken to the
// tetrahedron), and the rest are scaled to sum 1: w / w is exactly 1, so a point on a node
// interpolates to that node's value exactly.
std::array<double, 4> clamped(std::array<double, 4> w) {
  double sum = 0.0;
  for (double& x : w) {
    if (x < kLocateTolerance) x = 0.0;
    sum += x;
  }
  for (double& x : w) x /= sum;
  return w;
}

void bounding_box(const Mesh& mesh, int e, Eigen::Vector3d& low, Eigen::Vector3d& high) {
  const std::array<int, 4>& t = mesh.tetrahedra[static_cast<std::size_t>(e)];
  low = high = mesh.nodes[static_cast<std::size_t>(t[0])];
  for (int k = 1; k < 4; ++k) {
    low = low.cwiseMin(mesh.nodes[static_cast<std::size_t>(t[k])]);
    high = high.cwiseMax(mesh.nodes[static_cast<std::size_t>(t[k])]);
  }
}

// The point of triangle (a, b, c) nearest to p (Ericson, Real-Time Collision Detection,
// 5.1.5: find the Voronoi region of p among the corners, edges and the face).
Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                    const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + d1 / (d1 - d3) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0)
    return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denominator = 1.0 / (va + vb + vc);
  return a + ab * (vb * denominator) + ac * (vc * denominator);
}

// The point of tetrahedron e nearest to p, for a p outside it: on one of its faces.
Eigen::Vector3d closest_on_tetrahedron(const Mesh& mesh, int e, const Eigen::Vector3d& p) {
  const std::array<int, 4>& t = mesh.tetrahedra[static_cast<std::size_t>(e)];
  auto node = [&](int k) -> const Eigen::Vector3d& { return mesh.nodes[static_cast<std::size_t>(t[k])]; };
  constexpr int kFaces[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
  Eigen::Vector3d best = node(0);
  for (const auto& face : kFaces) {
    const Eigen::Vector3d q = closest_on_triangle(p, node(face[0]), node(face[1]), node(face[2]));
    if ((q - p).squaredNorm() < (best - p).squaredNorm()) best = q;
  }
  return best;
}

}  // namespace

MeshLocation locate_point(const Mesh& mesh, const Eigen::Vector3d& point) {
  if (mesh.tetrahedra.empty()) throw std::invalid_argument("locate_point: the mesh has no tetrahedra");
  MeshLocation found;
  double deepest = -std::numeric_limits<double>::infinity();   // the smallest weight there
  Eigen::Vector3d low, high;
  for (int e = 0; e < mesh.tetrahedron_count(); ++e) {
    bounding_box(mesh, e, low, high);
    const double slack = kLocateTolerance * (high - low).maxCoeff();
    if ((point.array() < low.array() - slack).any() || (point.array() > high.array() + slack).any())
      continue;
    const std::array<double, 4> w = barycentric(mesh, e, point);
    const double smallest = *std::min_element(w.begin(), w.end());
    if (smallest >= -kLocateTolerance && smallest > deepest) {
      deepest = smallest;
      found.tetrahedron = e;
      found.weights = clamped(w);
    }
  }
  if (found.tetrahedron >= 0) return found;

  // Outside every tetrahedron: the nearest one. A tetrahedron whose bounding box is farther
  // than the best distance so far cannot be nearer.
  double best = std::numeric_limits<double>::infinity();
  Eigen::Vector3d nearest = point;
  for (int e = 0; e < mesh.tetrahedron_count(); ++e) {
    bounding_box(mesh, e, low, high);
    const double box_distance = (point.cwiseMax(low).cwiseMin(high) - point).norm();
    if (box_distance >= best) continue;
    const Eigen::Vector3d q = closest_on_tetrahedron(mesh, e, point);
    const double distance = (q - point).norm();
    if (distance < best) {
      best = distance;
      nearest = q;
      found.tetrahedron = e;
    }
  }
  found.weights = clamped(barycentric(mesh, found.tetrahedron, nearest));
  found.outside_distance = best;
  return found;
}

double bounding_diagonal(const Mesh& mesh) {
  Eigen::Vector3d low = mesh.nodes.front(), high = mesh.nodes.front();
  for (const Eigen::Vector3d& p : mesh.nodes) {
    low = low.cwiseMin(p);
    high = high.cwiseMax(p);
  }
  return (high - low).norm();
}

}  // namespace sigmafem
