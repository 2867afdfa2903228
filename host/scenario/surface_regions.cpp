#include "host/scenario/surface_regions.h"

#include <algorithm>
#include <limits>

namespace sigmafem {

std::vector<Ligament> automatic_surface_regions(const Mesh& mesh, int count, const std::vector<int>& excluded) {
  std::vector<int> nodes;
  for (int node : boundary_nodes(mesh))
    if (std::find(excluded.begin(), excluded.end(), node) == excluded.end()) nodes.push_back(node);
  const int n = static_cast<int>(nodes.size());
  count = std::min(count, n);
  if (count <= 0) return {};
  auto position = [&](int i) -> Eigen::Vector3d { return mesh.nodes[static_cast<std::size_t>(nodes[i])]; };

  // Farthest-point seeds: spread over the surface, the same on every run.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (int i = 0; i < n; ++i) centroid += position(i) / n;
  std::vector<Eigen::Vector3d> centres;
  std::vector<double> distance(static_cast<std::size_t>(n), std::numeric_limits<double>::infinity());
  int next = 0;
  for (int i = 1; i < n; ++i)
    if ((position(i) - centroid).squaredNorm() > (position(next) - centroid).squaredNorm()) next = i;
  while (static_cast<int>(centres.size()) < count) {
    centres.push_back(position(next));
    for (int i = 0; i < n; ++i)
      distance[i] = std::min(distance[i], (position(i) - centres.back()).squaredNorm());
    next = static_cast<int>(std::max_element(distance.begin(), distance.end()) - distance.begin());
  }

  // Lloyd iterations: each node to its nearest centre, each centre to its nodes' mean.
  std::vector<int> label(static_cast<std::size_t>(n), -1);
  for (int iteration = 0; iteration < 100; ++iteration) {
    bool changed = false;
    for (int i = 0; i < n; ++i) {
      int best = 0;
      for (int c = 1; c < count; ++c)
        if ((position(i) - centres[c]).squaredNorm() < (position(i) - centres[best]).squaredNorm()) best = c;
      changed = changed || label[i] != best;
      label[i] = best;
    }
    if (!changed) break;
    std::vector<Eigen::Vector3d> sum(static_cast<std::size_t>(count), Eigen::Vector3d::Zero());
    std::vector<int> members(static_cast<std::size_t>(count), 0);
    for (int i = 0; i < n; ++i) sum[label[i]] += position(i), ++members[label[i]];
    for (int c = 0; c < count; ++c)
      if (members[c] > 0) centres[c] = sum[c] / members[c];
  }

  std::vector<Ligament> regions;
  for (int c = 0; c < count; ++c) {
    Ligament region;
    region.name = "surface_" + std::to_string(c + 1);
    for (int i = 0; i < n; ++i)
      if (label[i] == c) region.nodes.push_back(nodes[i]);
    if (!region.nodes.empty()) regions.push_back(std::move(region));
  }
  return regions;
}

}  // namespace sigmafem
