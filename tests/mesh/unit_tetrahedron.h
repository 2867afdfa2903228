// The unit tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1), positively oriented: the smallest
// mesh the mesh tests start from.
#pragma once

#include "host/mesh/mesh.h"

namespace sigmafem {

inline Mesh unit_tetrahedron() {
  Mesh mesh;
  mesh.nodes = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  mesh.tetrahedra = {{0, 1, 2, 3}};
  return mesh;
}

}  // namespace sigmafem
