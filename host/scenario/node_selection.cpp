// Node selection for scenario node sets (`select` in docs/FORMATS.md): every node within a
// radius of a point, or every node inside an axis-aligned box; and the same for the elements
// of a region, by their centroids. Coordinates are the mesh's
// current ones, i.e. metres once the scenario's scale/translate has been applied.
#include "host/scenario/scenario.h"

namespace sigmafem {

std::vector<int> select_nodes_near(const Mesh& mesh, const Eigen::Vector3d& near, double radius) {
  std::vector<int> selected;
  // Compare distances, not squared distances: the slack is a length and must not shrink
  // with the radius.
  for (int i = 0; i < mesh.node_count(); ++i) {
    if ((mesh.nodes[static_cast<size_t>(i)] - near).norm() <= radius + kSelectionSlack) {
      selected.push_back(i);
    }
  }
  return selected;
}

std::vector<int> select_nodes_in_box(const Mesh& mesh, const Eigen::Vector3d& min,
                                     const Eigen::Vector3d& max) {
  std::vector<int> selected;
  for (int i = 0; i < mesh.node_count(); ++i) {
    const Eigen::Vector3d& p = mesh.nodes[static_cast<size_t>(i)];
    const bool inside = (p.array() >= min.array() - kSelectionSlack).all() &&
                        (p.array() <= max.array() + kSelectionSlack).all();
    if (inside) selected.push_back(i);
  }
  return selected;
}

std::vector<int> select_elements(const Mesh& mesh, const NodeSetSpec& selection) {
  std::vector<int> selected;
  for (int e = 0; e < mesh.tetrahedron_count(); ++e) {
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (int node : mesh.tetrahedra[static_cast<size_t>(e)]) centroid += 0.25 * mesh.nodes[static_cast<size_t>(node)];
    bool inside = false;
    if (selection.kind == NodeSetSpec::Kind::near)
      inside = (centroid - selection.near).norm() <= selection.radius + kSelectionSlack;
    else if (selection.kind == NodeSetSpec::Kind::box)
      inside = (centroid.array() >= selection.min.array() - kSelectionSlack).all() &&
               (centroid.array() <= selection.max.array() + kSelectionSlack).all();
    if (inside) selected.push_back(e);
  }
  return selected;
}

std::vector<int> region_elements(const Mesh& mesh, const Region& region) {
  if (!region.label) return select_elements(mesh, region.selection);
  std::vector<int> elements;
  for (std::size_t e = 0; e < mesh.labels.size(); ++e)
    if (mesh.labels[e] == *region.label) elements.push_back(static_cast<int>(e));
  return elements;
}

}  // namespace sigmafem
