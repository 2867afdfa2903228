#include "host/mesh/observed_points.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace sigmafem {

ObservedPoint ObservedPoint::at_node(int node) {
  ObservedPoint point;
  point.nodes = {node, node, node, node};
  point.weights = {1.0, 0.0, 0.0, 0.0};
  return point;
}

ObservedPoint ObservedPoint::at(const Mesh& mesh, const MeshLocation& location) {
  ObservedPoint point;
  point.nodes = mesh.tetrahedra[static_cast<std::size_t>(location.tetrahedron)];
  point.weights = location.weights;
  // A point on a node (locate_point gives it weight exactly 1 there) is that node.
  for (std::size_t c = 0; c < 4; ++c)
    if (point.weights[c] == 1.0) return at_node(point.nodes[c]);
  return point;
}

Eigen::Vector3d ObservedPoint::of(const Eigen::VectorXd& field) const {
  Eigen::Vector3d value = Eigen::Vector3d::Zero();
  for (std::size_t c = 0; c < 4; ++c) value += weights[c] * field.segment<3>(3 * nodes[c]);
  return value;
}

Eigen::Vector3d ObservedPoint::at_rest(const Mesh& mesh) const {
  Eigen::Vector3d value = Eigen::Vector3d::Zero();
  for (std::size_t c = 0; c < 4; ++c) value += weights[c] * mesh.nodes[static_cast<std::size_t>(nodes[c])];
  return value;
}

int ObservedPoint::nearest_node() const {
  return nodes[static_cast<std::size_t>(std::max_element(weights.begin(), weights.end()) - weights.begin())];
}

ObservedPoints::ObservedPoints(const std::vector<int>& nodes) {
  reserve(nodes.size());
  for (int node : nodes) push_back(ObservedPoint::at_node(node));
}

std::vector<int> corner_nodes(const ObservedPoints& points) {
  std::vector<int> nodes;
  for (const ObservedPoint& point : points) nodes.insert(nodes.end(), point.nodes.begin(), point.nodes.end());
  if (nodes.empty()) nodes.assign(4, 0);
  return nodes;
}

std::vector<double> corner_weights(const ObservedPoints& points) {
  std::vector<double> weights;
  for (const ObservedPoint& point : points)
    weights.insert(weights.end(), point.weights.begin(), point.weights.end());
  if (weights.empty()) weights.assign(4, 0.0);
  return weights;
}

void check_observed_points(const ObservedPoints& points, int node_count, const char* who) {
  for (std::size_t k = 0; k < points.size(); ++k)
    for (int node : points[k].nodes)
      if (node < 0 || node >= node_count)
        throw std::invalid_argument(std::string(who) + ": observed point " + std::to_string(k) +
                                    " uses node " + std::to_string(node) + ", which does not exist");
}

}  // namespace sigmafem
