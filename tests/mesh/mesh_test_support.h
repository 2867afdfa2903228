// Helpers for the mesh tests: where the data is, a temporary folder that cleans up after
// itself, small writers that put a Mesh into each format read_mesh accepts (so one mesh can
// be read back through every reader and compared), and the checks that a set of faces is
// the closed, outward oriented surface of a mesh.
//
// The writers deliberately exercise what a reader must get right: node ids that are neither
// 1..n nor increasing (ids are decreasing, so file order and id order differ), elements of
// other types mixed in before and between the tetrahedra, and sections the reader must skip.
// Coordinates are written with 17 significant digits, so ASCII round trips are exact.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Geometry>  // cross()
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "temp_path.h"
#include "host/common/input_error.h"
#include "host/mesh/mesh.h"

namespace sigmafem::test {

inline std::string shared_data(const std::string& relative) {
  return std::string(SIGMAFEM_SHARED_DIR) + "/" + relative;
}
inline std::string source_file(const std::string& relative) {
  return std::string(SIGMAFEM_SOURCE_DIR) + "/" + relative;
}
inline std::string liver_msh() { return shared_data("data/liver/liver.msh"); }
inline std::string liver2_msh() { return shared_data("data/liver/liver2.msh"); }
inline std::string box_msh() { return source_file("scenarios/box.msh"); }


// The id a writer gives node i of n: decreasing and not starting at 1.
inline long long node_id(const Mesh& mesh, int i) { return 2LL * (mesh.node_count() - i) + 5; }

inline std::string format_real(double x) {
  std::ostringstream out;
  out.precision(17);
  out << x;
  return out.str();
}

inline std::string node_xyz(const Mesh& mesh, int i) {
  return format_real(mesh.nodes[i].x()) + " " + format_real(mesh.nodes[i].y()) + " " +
         format_real(mesh.nodes[i].z());
}

// Gmsh 1.0: $NOD / $ELM, with a line (type 1) and a triangle (type 2) before the tetrahedra.
inline std::string gmsh10_text(const Mesh& mesh) {
  std::ostringstream out;
  out << "$NOD\n" << mesh.node_count() << "\n";
  for (int i = 0; i < mesh.node_count(); ++i)
    out << node_id(mesh, i) << " " << node_xyz(mesh, i) << "\n";
  out << "$ENDNOD\n$ELM\n" << mesh.tetrahedron_count() + 2 << "\n";
  const auto& t0 = mesh.tetrahedra[0];
  out << "1 1 1 1 2 " << node_id(mesh, t0[0]) << " " << node_id(mesh, t0[1]) << "\n";
  out << "2 2 1 1 3 " << node_id(mesh, t0[0]) << " " << node_id(mesh, t0[1]) << " "
      << node_id(mesh, t0[2]) << "\n";
  for (int e = 0; e < mesh.tetrahedron_count(); ++e) {
    out << e + 3 << " 4 2 2 4";
    for (const int n : mesh.tetrahedra[e]) out << " " << node_id(mesh, n);
    out << "\n";
  }
  out << "$ENDELM\n";
  return out.str();
}

// Gmsh 2.2 with $PhysicalNames, a triangle with 2 tags and tetrahedra with 3 tags (the
// third a partition tag, as partitioned meshes have), and CRLF line ends.
inline std::string gmsh22_text(const Mesh& mesh) {
  std::ostringstream out;
  out << "$MeshFormat\r\n2.2 0 8\r\n$EndMeshFormat\r\n";
  out << "$PhysicalNames\r\n1\r\n3 1 \"organ with $Nodes in its name\"\r\n$EndPhysicalNames\r\n";
  out << "$Nodes\r\n" << mesh.node_count() << "\r\n";
  for (int i = 0; i < mesh.node_count(); ++i)
    out << node_id(mesh, i) << " " << node_xyz(mesh, i) << "\r\n";
  out << "$EndNodes\r\n$Elements\r\n" << mesh.tetrahedron_count() + 1 << "\r\n";
  const auto& t0 = mesh.tetrahedra[0];
  out << "900 2 2 7 7 " << node_id(mesh, t0[0]) << " " << node_id(mesh, t0[1]) << " "
      << node_id(mesh, t0[2]) << "\r\n";
  for (int e = 0; e < mesh.tetrahedron_count(); ++e) {
    out << e + 1 << " 4 3 1 1 2";
    for (const int n : mesh.tetrahedra[e]) out << " " << node_id(mesh, n);
    out << "\r\n";
  }
  out << "$EndElements\r\n";
  return out.str();
}

// Gmsh 4.1: $Entities (skipped), nodes in two blocks (the second parametric on a volume, with
// u v w after x y z), elements as a triangle block then two tetrahedron blocks.
inline std::string gmsh41_text(const Mesh& mesh) {
  const int n = mesh.node_count();
  const int first_block = n / 3;
  std::ostringstream out;
  out << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  out << "$Entities\n0 0 1 1\n1 0 0 0 1 1 1 0 1 0\n1 0 0 0 1 1 1 1 1 0 6 1 2 3 4 5 "
         "6\n$EndEntities\n";
  out << "$Nodes\n2 " << n << " 7 " << 2 * n + 5 << "\n";
  out << "2 1 0 " << first_block << "\n";
  for (int i = 0; i < first_block; ++i) out << node_id(mesh, i) << "\n";
  for (int i = 0; i < first_block; ++i) out << node_xyz(mesh, i) << "\n";
  out << "3 1 1 " << n - first_block << "\n";
  for (int i = first_block; i < n; ++i) out << node_id(mesh, i) << "\n";
  for (int i = first_block; i < n; ++i) out << node_xyz(mesh, i) << " 0.25 0.5 0.75\n";
  out << "$EndNodes\n";
  const int tets = mesh.tetrahedron_count();
  const int first_tets = tets / 2;
  const auto& t0 = mesh.tetrahedra[0];
  out << "$Elements\n3 " << tets + 1 << " 1 " << tets + 1 << "\n";
  out << "2 1 2 1\n"
      << tets + 1 << " " << node_id(mesh, t0[0]) << " " << node_id(mesh, t0[1]) << " "
      << node_id(mesh, t0[2]) << "\n";
  for (int block = 0; block < 2; ++block) {
    const int begin = block == 0 ? 0 : first_tets;
    const int end = block == 0 ? first_tets : tets;
    out << "3 1 4 " << end - begin << "\n";
    for (int e = begin; e < end; ++e) {
      out << e + 1;
      for (const int k : mesh.tetrahedra[e]) out << " " << node_id(mesh, k);
      out << "\n";
    }
  }
  out << "$EndElements\n";
  return out.str();
}

// Legacy VTK 3.0 ASCII, a vertex cell (type 1) and a triangle (type 5) before the tetrahedra,
// points 2 per line and cells split oddly: values are separated by any white space.
inline std::string vtk_ascii_text(const Mesh& mesh) {
  std::ostringstream out;
  out << "# vtk DataFile Version 3.0\nwritten by the sigmafem mesh tests\nASCII\n"
      << "DATASET UNSTRUCTURED_GRID\nPOINTS " << mesh.node_count() << " double\n";
  for (int i = 0; i < mesh.node_count(); ++i) out << node_xyz(mesh, i) << (i % 2 ? "\n" : " ");
  const int cells = mesh.tetrahedron_count() + 2;
  out << "\nCELLS " << cells << " " << 5 * mesh.tetrahedron_count() + 2 + 4 << "\n";
  const auto& t0 = mesh.tetrahedra[0];
  out << "1 " << t0[0] << "\n3 " << t0[0] << " " << t0[1] << " " << t0[2] << "\n";
  for (const auto& t : mesh.tetrahedra)
    out << "4 " << t[0] << " " << t[1] << "\n" << t[2] << " " << t[3] << "\n";
  out << "CELL_TYPES " << cells << "\n1\n5\n";
  for (int e = 0; e < mesh.tetrahedron_count(); ++e) out << "10\n";
  // The mesh's labels (1 without), 7 for the vertex and the triangle, which are no tetrahedra.
  out << "CELL_DATA " << cells << "\nSCALARS region int 1\nLOOKUP_TABLE default\n7\n7\n";
  for (int e = 0; e < mesh.tetrahedron_count(); ++e)
    out << (mesh.labels.empty() ? 1 : mesh.labels[static_cast<std::size_t>(e)]) << "\n";
  return out.str();
}

// Big-endian bytes of a 32- or 64-bit value, as legacy VTK BINARY stores every number.
template <typename T>
void put_big_endian(std::ostream& out, T value) {
  static_assert(sizeof(T) == 4 || sizeof(T) == 8, "VTK binary numbers here are 4 or 8 bytes");
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  for (std::size_t i = sizeof(T); i-- > 0;) out.put(static_cast<char>(bytes[i]));
}

// Legacy VTK BINARY, classic CELLS layout; points as double (exact) or float.
inline std::string vtk_binary_text(const Mesh& mesh, bool as_double = true) {
  std::ostringstream out;
  out << "# vtk DataFile Version 3.0\nbinary test mesh\nBINARY\nDATASET UNSTRUCTURED_GRID\n";
  out << "FIELD FieldData 1\nTIME 1 1 double\n";
  put_big_endian(out, 0.5);
  out << "\nPOINTS " << mesh.node_count() << (as_double ? " double\n" : " float\n");
  for (const auto& x : mesh.nodes) {
    for (int k = 0; k < 3; ++k) {
      if (as_double) {
        put_big_endian(out, x[k]);
      } else {
        put_big_endian(out, static_cast<float>(x[k]));
      }
    }
  }
  const int cells = mesh.tetrahedron_count() + 1;
  out << "\nCELLS " << cells << " " << 5 * mesh.tetrahedron_count() + 4 << "\n";
  const auto& t0 = mesh.tetrahedra[0];
  for (const std::int32_t v : {3, t0[0], t0[1], t0[2]}) put_big_endian(out, v);
  for (const auto& t : mesh.tetrahedra) {
    put_big_endian(out, std::int32_t{4});
    for (const int n : t) put_big_endian(out, static_cast<std::int32_t>(n));
  }
  out << "\nCELL_TYPES " << cells << "\n";
  put_big_endian(out, std::int32_t{5});
  for (int e = 0; e < mesh.tetrahedron_count(); ++e) put_big_endian(out, std::int32_t{10});
  out << "\n";
  return out.str();
}

// Legacy VTK 5.1 (what VTK 9 writes): CELLS as OFFSETS + CONNECTIVITY, 64-bit in BINARY.
inline std::string vtk51_text(const Mesh& mesh, bool binary) {
  std::ostringstream out;
  out << "# vtk DataFile Version 5.1\nvtk 5.1 test mesh\n"
      << (binary ? "BINARY" : "ASCII") << "\nDATASET UNSTRUCTURED_GRID\nPOINTS "
      << mesh.node_count() << " double\n";
  for (int i = 0; i < mesh.node_count(); ++i) {
    if (binary) {
      for (int k = 0; k < 3; ++k) put_big_endian(out, mesh.nodes[i][k]);
    } else {
      out << node_xyz(mesh, i) << "\n";
    }
  }
  if (!binary) out << "METADATA\nINFORMATION 0\n\n";
  const int tets = mesh.tetrahedron_count();
  out << (binary ? "\n" : "") << "CELLS " << tets + 1 << " " << 4 * tets << "\n";
  out << "OFFSETS vtktypeint64\n";
  for (int e = 0; e <= tets; ++e) {
    if (binary) {
      put_big_endian(out, std::int64_t{4} * e);
    } else {
      out << 4 * e << "\n";
    }
  }
  out << (binary ? "\n" : "") << "CONNECTIVITY vtktypeint64\n";
  for (const auto& t : mesh.tetrahedra) {
    for (const int n : t) {
      if (binary) {
        put_big_endian(out, static_cast<std::int64_t>(n));
      } else {
        out << n << " ";
      }
    }
    if (!binary) out << "\n";
  }
  out << (binary ? "\n" : "") << "CELL_TYPES " << tets << "\n";
  for (int e = 0; e < tets; ++e) {
    if (binary) {
      put_big_endian(out, std::int32_t{10});
    } else {
      out << "10\n";
    }
  }
  return out.str();
}

// Reads `content` (written to a temporary file named `name`) and returns the InputError
// message; fails the test if reading succeeds or throws anything else.
inline std::string read_error(const std::string& name, const std::string& content) {
  TempDir dir;
  const std::string path = dir.write(name, content);
  try {
    read_mesh(path);
  } catch (const InputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "reading " << name << " should have thrown InputError";
  return {};
}

// Checks that `faces` is a closed surface with outward normals around `mesh`:
//  - every directed edge (a -> b) of a face appears once and its reverse (b -> a) once, so
//    the surface is closed, manifold and consistently oriented;
//  - the area vectors sum to zero (true of any closed surface);
//  - by the divergence theorem with F(x) = x / 3, the sum over faces of (centroid . n A) / 3
//    equals the enclosed volume: positive and equal to the mesh volume only when n points out.
inline void expect_closed_outward_surface(const Mesh& mesh,
                                          const std::vector<std::array<int, 3>>& faces,
                                          const std::string& what) {
  std::map<std::pair<int, int>, int> directed_edges;
  Eigen::Vector3d area_sum = Eigen::Vector3d::Zero();
  double area_total = 0.0;
  double flux_volume = 0.0;
  for (const auto& f : faces) {
    for (int k = 0; k < 3; ++k) ++directed_edges[{f[k], f[(k + 1) % 3]}];
    const Eigen::Vector3d& a = mesh.nodes[f[0]];
    const Eigen::Vector3d area = 0.5 * (mesh.nodes[f[1]] - a).cross(mesh.nodes[f[2]] - a);
    area_sum += area;
    area_total += area.norm();
    flux_volume += (a + mesh.nodes[f[1]] + mesh.nodes[f[2]]).dot(area) / 9.0;
  }
  for (const auto& [edge, count] : directed_edges) {
    ASSERT_EQ(count, 1) << what << ": edge " << edge.first << " -> " << edge.second
                        << " is used by " << count << " faces in the same direction";
    const auto reverse = directed_edges.find({edge.second, edge.first});
    ASSERT_TRUE(reverse != directed_edges.end())
        << what << ": edge " << edge.first << " -> " << edge.second
        << " has no face on its other side: the surface is not closed";
  }
  EXPECT_LT(area_sum.norm(), 1e-12 * area_total) << what << ": sum of area vectors";
  double volume = 0.0;
  for (int e = 0; e < mesh.tetrahedron_count(); ++e)
    volume += std::abs(tetrahedron_volume(mesh, e));
  EXPECT_NEAR(flux_volume, volume, 1e-12 * volume)
      << what << ": divergence theorem, the volume enclosed by the outward surface";
}

// `text` with the first `from` replaced by `to` (a test-setup failure if `from` is absent).
inline std::string replace(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "test setup: " << from << " not in the text";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// Reading `content` as file `name` must fail with "mesh <path>/<name>: ..." containing `expected`.
inline void expect_read_error(const std::string& name, const std::string& content,
                              const std::string& expected) {
  const std::string message = read_error(name, content);
  EXPECT_EQ(message.rfind("mesh ", 0), 0u) << message;
  EXPECT_NE(message.find(name + ": "), std::string::npos) << "names the file: " << message;
  EXPECT_NE(message.find(expected), std::string::npos)
      << "expected \"" << expected << "\" in: " << message;
}

}  // namespace sigmafem::test
