// read_mesh: loads a mesh file and hands its content to the reader for its format, chosen by
// content rather than by extension (a Gmsh file saved as .txt still reads; a .msh that is
// really something else gets a message saying what was found). transform_mesh: file units
// to metres.
//
// The whole file is read into memory first: meshes sigmafem runs are at most a few hundred
// thousand elements (tens of MB), and the readers can then check counts against the bytes
// that are left instead of trusting a corrupt header.
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <string_view>

#include "host/common/input_error.h"
#include "host/common/input_file.h"
#include "host/mesh/mesh.h"
#include "host/mesh/mesh_formats.h"
#include "host/mesh/text_cursor.h"

namespace sigmafem {

namespace {

bool starts_with(std::string_view text, std::string_view prefix) {
  return text.substr(0, prefix.size()) == prefix;
}

std::string_view first_line(std::string_view text) {
  std::string_view line = text.substr(0, text.find('\n'));
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  return line;
}

}  // namespace

Mesh read_mesh(const std::string& path) {
  const std::string content = read_input_file(path, "mesh " + path, kMaxMeshBytes);
  // A UTF-8 byte order mark, as some Windows editors save, is not part of either format.
  const std::string_view text = without_byte_order_mark(content);

  const std::size_t first = text.find_first_not_of(" \t\r\n");
  if (first == std::string_view::npos) throw_mesh_error(path, "the file is empty");
  const std::string_view start = text.substr(first);
  // VTK requires its header on line 1; Gmsh tolerates blank lines before $MeshFormat.
  if (starts_with(text, "# vtk DataFile")) return read_vtk(text, path);
  if (starts_with(start, "$")) return read_gmsh(text, path);
  if (starts_with(start, "<?xml") || starts_with(start, "<VTKFile")) {
    throw_mesh_error(path,
                     "XML VTK files (.vtu) are not supported; save the mesh as a legacy "
                     ".vtk unstructured grid or a Gmsh .msh");
  }
  throw_mesh_error(path,
                   "not a mesh file sigmafem reads: expected Gmsh ($MeshFormat or $NOD) "
                   "or legacy VTK (# vtk DataFile) at the start, found " +
                       quote_for_message(first_line(start)));
}

void transform_mesh(Mesh& mesh, double scale, const Eigen::Vector3d& translate) {
  if (!(std::isfinite(scale) && scale > 0.0) || !translate.allFinite()) {
    std::ostringstream message;
    message << "mesh transform: scale must be a positive number and translate finite, got scale "
            << scale << ", translate [" << translate.transpose() << "]";
    throw InputError(message.str());
  }
  for (Eigen::Vector3d& x : mesh.nodes) x = scale * x + translate;
}

}  // namespace sigmafem
