#include "host/generator/spring_spread.h"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <map>

namespace sigmafem {
namespace {

// Barycentric weights of p in tetrahedron t of `mesh`.
Eigen::Vector4d barycentric(const Mesh& mesh, const std::array<int, 4>& t, const Eigen::Vector3d& p) {
  Eigen::Matrix3d edges;
  for (int c = 0; c < 3; ++c) edges.col(c) = mesh.nodes[t[c + 1]] - mesh.nodes[t[0]];
  const Eigen::Vector3d w = edges.partialPivLu().solve(p - mesh.nodes[t[0]]);
  return {1.0 - w.sum(), w[0], w[1], w[2]};
}

// Lumped measure of every node of `fine`: a third of the area of each boundary triangle it
// is a corner of (`surface`), or a quarter of the volume of each tetrahedron.
std::vector<double> lumped_measure(const Mesh& fine, bool surface) {
  std::vector<double> measure(fine.nodes.size(), 0.0);
  if (surface) {
    for (const std::array<int, 3>& f : boundary_faces(fine)) {
      const double area =
          0.5 * (fine.nodes[f[1]] - fine.nodes[f[0]]).cross(fine.nodes[f[2]] - fine.nodes[f[0]]).norm();
      for (int n : f) measure[n] += area / 3.0;
    }
  } else {
    for (int e = 0; e < fine.tetrahedron_count(); ++e)
      for (int n : fine.tetrahedra[e]) measure[n] += std::abs(tetrahedron_volume(fine, e)) / 4.0;
  }
  return measure;
}

}  // namespace

std::vector<SpringShare> spread_spring(const Mesh& coarse, const std::vector<int>& coarse_nodes, const Mesh& fine) {
  // A shape function's value below this counts as 0: a refined node on the support's boundary
  // (rounding puts it a hair inside or out) takes nothing.
  constexpr double kZero = 1e-9;
  const std::vector<int> coarse_boundary = boundary_nodes(coarse);
  std::vector<double> area, volume;   // computed when first needed
  std::map<int, double> shares;
  for (int i : coarse_nodes) {
    const bool on_surface = std::binary_search(coarse_boundary.begin(), coarse_boundary.end(), i);
    std::vector<double>& measure = on_surface ? area : volume;
    if (measure.empty()) measure = lumped_measure(fine, on_surface);
    // phi_i at every refined node inside its support (the coarse tetrahedra around i).
    std::map<int, double> phi;
    for (const std::array<int, 4>& t : coarse.tetrahedra) {
      const auto corner = std::find(t.begin(), t.end(), i) - t.begin();
      if (corner == 4) continue;
      Eigen::Vector3d low = coarse.nodes[t[0]], high = low;
      for (int n : t) low = low.cwiseMin(coarse.nodes[n]), high = high.cwiseMax(coarse.nodes[n]);
      const double slack = kZero * (high - low).norm();
      for (int j = 0; j < fine.node_count(); ++j) {
        const Eigen::Vector3d& p = fine.nodes[static_cast<std::size_t>(j)];
        if ((p.array() < low.array() - slack).any() || (p.array() > high.array() + slack).any()) continue;
        const Eigen::Vector4d w = barycentric(coarse, t, p);
        if (w.minCoeff() < -kZero || w[corner] <= kZero || measure[static_cast<std::size_t>(j)] <= 0.0) continue;
        phi[j] = w[corner];   // the same on every tetrahedron of the support that holds j
      }
    }
    double total = 0.0;
    for (const auto& [j, value] : phi) total += value * measure[static_cast<std::size_t>(j)];
    for (const auto& [j, value] : phi)
      shares[j] += value * measure[static_cast<std::size_t>(j)] / total / static_cast<double>(coarse_nodes.size());
  }
  std::vector<SpringShare> out;
  for (const auto& [node, share] : shares) out.push_back({node, share});
  return out;
}

}  // namespace sigmafem
