// Boundary surface of a tetrahedral mesh (mesh.h: boundary_faces, boundary_nodes).
//
// A face is on the boundary when exactly one tetrahedron uses it. Faces are matched by their
// sorted node triple: all 4 x (tetrahedra) faces are sorted by that key, so equal faces
// become neighbours. That is O(n log n), needs no hash, and gives the same result on every
// run. Boundary faces come out in element order, then local face order.
//
// Orientation: for a positively oriented tetrahedron (a, b, c, d), the faces
// (b, c, d), (a, d, c), (a, b, d), (a, c, b), opposite a, b, c, d in turn, have outward normals
// by the right-hand rule. A tetrahedron still given with negative orientation (a mesh that did
// not go through orient_and_check) gets its faces reversed, so the normals are outward anyway.
#include <algorithm>
#include <array>
#include <utility>
#include <vector>

#include "host/mesh/mesh.h"

namespace sigmafem {

namespace {

// Local corners of the face opposite corner f, outward for a positive tetrahedron.
constexpr int kOutwardFaces[4][3] = {{1, 2, 3}, {0, 3, 2}, {0, 1, 3}, {0, 2, 1}};

std::array<int, 3> outward_face(const Mesh& mesh, int e, int f) {
  const std::array<int, 4>& t = mesh.tetrahedra[e];
  std::array<int, 3> face = {t[kOutwardFaces[f][0]], t[kOutwardFaces[f][1]],
                             t[kOutwardFaces[f][2]]};
  if (tetrahedron_volume(mesh, e) < 0.0) std::swap(face[1], face[2]);
  return face;
}

}  // namespace

std::vector<std::array<int, 3>> boundary_faces(const Mesh& mesh) {
  // (sorted nodes, 4 * element + local face) for every face of every element.
  std::vector<std::pair<std::array<int, 3>, int>> faces;
  faces.reserve(4 * mesh.tetrahedra.size());
  for (int e = 0; e < mesh.tetrahedron_count(); ++e) {
    for (int f = 0; f < 4; ++f) {
      std::array<int, 3> key = {mesh.tetrahedra[e][kOutwardFaces[f][0]],
                                mesh.tetrahedra[e][kOutwardFaces[f][1]],
                                mesh.tetrahedra[e][kOutwardFaces[f][2]]};
      std::sort(key.begin(), key.end());
      faces.emplace_back(key, 4 * e + f);
    }
  }
  std::sort(faces.begin(), faces.end());

  std::vector<int> once;  // 4 * element + local face of the faces used by one element
  for (std::size_t i = 0; i < faces.size();) {
    std::size_t j = i + 1;
    while (j < faces.size() && faces[j].first == faces[i].first) ++j;
    if (j - i == 1) once.push_back(faces[i].second);
    i = j;
  }
  std::sort(once.begin(), once.end());

  std::vector<std::array<int, 3>> boundary;
  boundary.reserve(once.size());
  for (const int id : once) boundary.push_back(outward_face(mesh, id / 4, id % 4));
  return boundary;
}

std::vector<int> boundary_nodes(const Mesh& mesh) {
  std::vector<int> nodes;
  for (const std::array<int, 3>& face : boundary_faces(mesh)) {
    nodes.insert(nodes.end(), face.begin(), face.end());
  }
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

BoundarySurface boundary_surface(const Mesh& mesh) {
  BoundarySurface surface;
  surface.nodes = boundary_nodes(mesh);
  for (std::array<int, 3> face : boundary_faces(mesh)) {
    for (int& v : face)
      v = static_cast<int>(std::lower_bound(surface.nodes.begin(), surface.nodes.end(), v) - surface.nodes.begin());
    surface.triangles.push_back(face);
  }
  return surface;
}

}  // namespace sigmafem
