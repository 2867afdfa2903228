// The points an ensemble observes. Each is a material point of the mesh: a node, or a point in
// (or on) a tetrahedron, held as that tetrahedron's four nodes and the point's barycentric
// weights there, as SOFA's BarycentricMapping maps points onto a mesh (docs/FORMATS.md,
// `observations.points`). Its position in a state x is sum_c w_c x(node_c): it moves with its
// tetrahedron, and at rest it is where it was given. A node is {n, n, n, n} with weights
// {1, 0, 0, 0}, which gives the node's own value bit for bit (1 x + 0 x' = x).
#pragma once

#include <Eigen/Core>
#include <array>
#include <vector>

#include "host/mesh/mesh.h"
#include "host/mesh/mesh_locate.h"

namespace sigmafem {

struct ObservedPoint {
  std::array<int, 4> nodes{};
  std::array<double, 4> weights{};

  // Node `node` itself.
  static ObservedPoint at_node(int node);
  // The point `location` describes in `mesh` (locate_point).
  static ObservedPoint at(const Mesh& mesh, const MeshLocation& location);
  // sum_c w_c field(node_c) for a field of 3 numbers per node (positions, displacements).
  Eigen::Vector3d of(const Eigen::VectorXd& field) const;
  // Where the point is on the mesh at rest.
  Eigen::Vector3d at_rest(const Mesh& mesh) const;
  // The node with the largest weight (the node itself for a node).
  int nearest_node() const;
};

// The observed points in order: the columns pK of observations.csv. Built implicitly from node
// indices (each node observed as itself), which is what an ensemble observed before points.
class ObservedPoints : public std::vector<ObservedPoint> {
 public:
  ObservedPoints() = default;
  ObservedPoints(const std::vector<int>& nodes);  // NOLINT: a node list is a list of points
  explicit ObservedPoints(std::vector<ObservedPoint> points)
      : std::vector<ObservedPoint>(std::move(points)) {}
};

// The points' nodes and weights, 4 per point in point order, for the device back ends'
// buffers (observation_gather); one unused point when there is none (no empty buffers).
std::vector<int> corner_nodes(const ObservedPoints& points);
std::vector<double> corner_weights(const ObservedPoints& points);

// Throws std::invalid_argument, naming `who`, when a point uses a node outside 0..node_count-1.
void check_observed_points(const ObservedPoints& points, int node_count, const char* who);

}  // namespace sigmafem
