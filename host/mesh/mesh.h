// Mesh: the tetrahedral volume mesh of an organ, in metres, with the operations sigmafem
// needs on it: reading (Gmsh ASCII 1.0, 2.2, 4.1; legacy VTK unstructured grids), mapping
// file units to metres, checking element quality and orientation, extracting the boundary
// surface, and uniform refinement.
//
// Conventions: node indices are 0-based in file order (the order nodes appear in the file,
// whatever ids the file gives them). A tetrahedron's nodes (a, b, c, d) are positively
// oriented: ((b - a) x (c - a)) . (d - a) > 0.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

namespace sigmafem {

// The six edges of a tetrahedron, as pairs of its corners (0-3).
inline constexpr int kTetrahedronEdges[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};

struct Mesh {
  std::vector<Eigen::Vector3d> nodes;            // positions, metres once transformed
  std::vector<std::array<int, 4>> tetrahedra;    // 0-based node indices, positively oriented
  // Per tetrahedron, the label the file gives it (Gmsh: its physical group, 0 when it has
  // none; VTK: its value in a CELL_DATA array of integers), for regions selected by label;
  // empty when the file gives none.
  std::vector<int> labels;
  // Where the labels come from ("physical groups", "CELL_DATA array ..."), or when there are
  // none, why: for the error of a scenario that selects a region by label.
  std::string labels_from;
  int node_count() const { return static_cast<int>(nodes.size()); }
  int tetrahedron_count() const { return static_cast<int>(tetrahedra.size()); }
};

// What orient_and_check found.
struct MeshQualityReport {
  int inverted_reordered = 0;      // tetrahedra given with negative orientation and fixed
  double min_quality = 0.0;        // smallest volume / (mean edge length)^3 over elements
  double total_volume = 0.0;       // sum of element volumes
};

// Reads a mesh file, choosing the reader by content (Gmsh 1.0 starts with $NOD, 2.2 and 4.1
// with $MeshFormat; VTK with "# vtk DataFile"). Only tetrahedra are kept (Gmsh element type 4,
// VTK cell type 10); other elements are ignored. Nodes that no tetrahedron uses are kept (so
// indices stay those of the file). Throws InputError naming the file and line on any
// malformed content, an unknown node id, or a file with no tetrahedra.
Mesh read_mesh(const std::string& path);

// x <- scale * x + translate for every node (scale > 0).
void transform_mesh(Mesh& mesh, double scale, const Eigen::Vector3d& translate);

// Checks every tetrahedron. Degenerate (|volume| below 1e-6 of (mean edge length)^3 / 6√2,
// i.e. a quality ratio far below a regular tetrahedron's): throws InputError naming
// `source` (the file), the element index and its nodes, and its volume. Inverted (negative
// volume): swaps two nodes so it is positive, and counts it.
MeshQualityReport orient_and_check(Mesh& mesh, const std::string& source);

// Signed volume of tetrahedron e.
double tetrahedron_volume(const Mesh& mesh, int e);

// Boundary surface: the faces used by exactly one tetrahedron, oriented with outward normal.
std::vector<std::array<int, 3>> boundary_faces(const Mesh& mesh);

// Sorted, unique indices of the nodes on the boundary surface.
std::vector<int> boundary_nodes(const Mesh& mesh);

// The boundary surface on its own nodes: `nodes` = boundary_nodes(mesh), and the faces of
// boundary_faces(mesh) with each corner an index into `nodes` (what an ensemble observing
// those nodes returns, in that order).
struct BoundarySurface {
  std::vector<int> nodes;
  std::vector<std::array<int, 3>> triangles;
};
BoundarySurface boundary_surface(const Mesh& mesh);

// Uniform refinement: each tetrahedron into eight (edge midpoints added as new nodes after
// the old ones, old nodes keep their indices; the interior octahedron split along its
// shortest diagonal). All children positively oriented, each with its parent's label.
Mesh refine_uniform(const Mesh& mesh);

}  // namespace sigmafem
