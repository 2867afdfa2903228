// The format readers behind read_mesh (mesh.h), one file each: mesh_gmsh.cpp, mesh_vtk.cpp.
// Internal to host/mesh/: read_mesh loads the file and picks the reader by content.
//
// Each reader takes the whole file content and the file name for messages, returns the
// tetrahedra as given in the file (orientation not yet checked: see orient_and_check), and
// throws InputError naming the file and line on anything malformed, including a file with no
// tetrahedra.
#pragma once

#include <climits>
#include <string>
#include <string_view>

#include "host/mesh/mesh.h"

namespace sigmafem {

// The largest node or element count a reader accepts: indices are ints (mesh.h).
inline constexpr long long kMaxMeshCount = INT_MAX;

// Gmsh ASCII: 1.0 (starts with $NOD), 2.x and 4.1 (start with $MeshFormat).
Mesh read_gmsh(std::string_view text, const std::string& source);

// Legacy VTK UNSTRUCTURED_GRID (starts with "# vtk DataFile"), ASCII or BINARY.
Mesh read_vtk(std::string_view text, const std::string& source);

}  // namespace sigmafem
