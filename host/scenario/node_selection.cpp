// Node selection for scenario node sets (`select` in docs/FORMATS.md): every node within a
// radius of a point, or every node inside an axis-aligned box. Coordinates are the mesh's
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

}  // namespace sigmafem
