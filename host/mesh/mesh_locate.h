// Point location in a tetrahedral mesh: which tetrahedron holds a point, and the point's
// barycentric weights there, so that a field given at the nodes (a displacement) can be
// interpolated at any point of the body. `generate --truth-refine/--truth-mesh` uses it to
// read the truth, simulated on another mesh, at the model's observed material points, and
// scenarios place observed points anywhere on the mesh (host/mesh/observed_points.h).
#pragma once

#include <Eigen/Core>
#include <array>

#include "host/mesh/mesh.h"

namespace sigmafem {

// Barycentric weights within this of 0 count as 0: a point on a face or an edge (rounding puts
// it a hair outside) is inside, and a point on a node gets weight exactly 1 there (so that
// interpolation returns the node's value bit for bit). Relative to the element's size.
constexpr double kLocateTolerance = 1e-9;

// Where a point lies: tetrahedron `tetrahedron` of the mesh, weights (w0..w3) of its nodes in
// the order mesh.tetrahedra lists them; each w >= 0 and they sum to 1.
struct MeshLocation {
  int tetrahedron = -1;
  std::array<double, 4> weights{};
  // 0 for a point inside the mesh (within kLocateTolerance); else its distance (m) to the
  // mesh, which the location then describes the nearest point of.
  double outside_distance = 0.0;
};

// A point given on a mesh but farther outside it than this share of its size
// (bounding_diagonal) is an error: faceting of a curved surface explains a fraction of a
// millimetre, not this; the point and the mesh are not of the same organ in the same frame.
constexpr double kMaxOutsideShare = 0.01;

// The diagonal of the mesh's bounding box (m).
double bounding_diagonal(const Mesh& mesh);

// Locates `point` in `mesh` (which must have a tetrahedron). Inside: the tetrahedron that
// holds it (on a shared face or edge, the one where it is deepest; any would interpolate
// alike). Outside, as a point on a curved surface can be when the other mesh's facets cut
// inside the curve: the nearest point of the nearest tetrahedron, whose weights are the
// point's clamped ones. Every tetrahedron is tried (cheap next to a simulation step for the
// few dozen observed points; no search structure to keep).
MeshLocation locate_point(const Mesh& mesh, const Eigen::Vector3d& point);

}  // namespace sigmafem
