// Uniform refinement of a tetrahedral mesh (mesh.h: refine_uniform), the red refinement of
// Bey ("Tetrahedral grid refinement", Computing 55, 1995): every edge is halved, each
// tetrahedron becomes four corner tetrahedra and an octahedron, and the octahedron is cut
// into four along one of its three diagonals.
//
// Numbering: old nodes keep their indices; the midpoint of each edge (shared by all elements
// around it, so the refined mesh is conforming) is added after them, edges in increasing
// (smaller node, larger node) order. Children of element e are 8e .. 8e + 7.
//
// Why the shortest diagonal: the corner children are similar to the parent, but the
// octahedron's children are not, and always cutting along the same diagonal lets their
// shape degrade from one refinement to the next; the shortest one keeps it bounded.
//
// Local numbering of the 10 nodes of one parent (a, b, c, d) = 0..3:
//   4 = mid(a,b)  5 = mid(a,c)  6 = mid(a,d)  7 = mid(b,c)  8 = mid(b,d)  9 = mid(c,d)
// The tables below give positive children for a positive parent: an affine map with
// positive determinant takes the reference tetrahedron to the parent, and in the reference
// tetrahedron each child was checked to have volume +1/8 of the parent's (and the test
// checks it again on real meshes).
#include <algorithm>
#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <utility>
#include <vector>

#include "host/mesh/mesh.h"

namespace sigmafem {

namespace {

// Edge k of kTetrahedronEdges (mesh.h) has its midpoint at local node 4 + k.
constexpr int kCornerChildren[4][4] = {{0, 4, 5, 6}, {4, 1, 7, 8}, {5, 7, 2, 9}, {6, 8, 9, 3}};

// The octahedron's diagonals join midpoints of opposite edges: (4,9), (5,8), (6,7). For each,
// the four tetrahedra (diagonal, then two consecutive nodes of the ring around it), with the
// ring walked in the direction that makes them positive.
constexpr int kDiagonals[3][2] = {{4, 9}, {5, 8}, {6, 7}};
constexpr int kOctahedronChildren[3][4][4] = {
    {{4, 9, 5, 6}, {4, 9, 6, 8}, {4, 9, 8, 7}, {4, 9, 7, 5}},
    {{5, 8, 4, 7}, {5, 8, 7, 9}, {5, 8, 9, 6}, {5, 8, 6, 4}},
    {{6, 7, 4, 5}, {6, 7, 5, 9}, {6, 7, 9, 8}, {6, 7, 8, 4}},
};

std::uint64_t edge_key(int a, int b) {
  if (a > b) std::swap(a, b);
  return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(a)) << 32) |
         static_cast<std::uint32_t>(b);
}

}  // namespace

Mesh refine_uniform(const Mesh& mesh) {
  std::vector<std::uint64_t> edges;
  edges.reserve(6 * mesh.tetrahedra.size());
  for (const std::array<int, 4>& t : mesh.tetrahedra) {
    for (const auto& edge : kTetrahedronEdges) edges.push_back(edge_key(t[edge[0]], t[edge[1]]));
  }
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());

  const std::size_t old_nodes = mesh.nodes.size();
  if (old_nodes + edges.size() > static_cast<std::size_t>(INT_MAX) ||
      mesh.tetrahedra.size() > static_cast<std::size_t>(INT_MAX / 8)) {
    throw std::length_error(
        "refine_uniform: the refined mesh would have more than INT_MAX "
        "nodes or elements");
  }

  Mesh refined;
  refined.nodes = mesh.nodes;
  refined.nodes.reserve(old_nodes + edges.size());
  for (const std::uint64_t key : edges) {
    const auto a = static_cast<int>(key >> 32);
    const auto b = static_cast<int>(key & 0xffffffffu);
    refined.nodes.push_back(0.5 * (mesh.nodes[a] + mesh.nodes[b]));
  }

  refined.tetrahedra.reserve(8 * mesh.tetrahedra.size());
  refined.labels_from = mesh.labels_from;
  if (!mesh.labels.empty())
    for (int label : mesh.labels) refined.labels.insert(refined.labels.end(), 8, label);   // the children's order below
  for (int e = 0; e < mesh.tetrahedron_count(); ++e) {
    std::array<int, 10> local;
    for (int k = 0; k < 4; ++k) local[k] = mesh.tetrahedra[e][k];
    // A parent given inverted is refined as its positive twin, so every child is positive.
    if (tetrahedron_volume(mesh, e) < 0.0) std::swap(local[2], local[3]);
    for (int k = 0; k < 6; ++k) {
      const std::uint64_t key = edge_key(local[kTetrahedronEdges[k][0]], local[kTetrahedronEdges[k][1]]);
      const auto position = std::lower_bound(edges.begin(), edges.end(), key) - edges.begin();
      local[4 + k] = static_cast<int>(old_nodes + static_cast<std::size_t>(position));
    }

    for (const auto& child : kCornerChildren) {
      refined.tetrahedra.push_back(
          {local[child[0]], local[child[1]], local[child[2]], local[child[3]]});
    }
    int shortest = 0;
    double shortest_length = HUGE_VAL;
    for (int d = 0; d < 3; ++d) {
      const double length =
          (refined.nodes[local[kDiagonals[d][0]]] - refined.nodes[local[kDiagonals[d][1]]])
              .squaredNorm();
      if (length < shortest_length) {
        shortest = d;
        shortest_length = length;
      }
    }
    for (const auto& child : kOctahedronChildren[shortest]) {
      refined.tetrahedra.push_back(
          {local[child[0]], local[child[1]], local[child[2]], local[child[3]]});
    }
  }
  return refined;
}

}  // namespace sigmafem
