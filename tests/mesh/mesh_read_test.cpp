// read_mesh and transform_mesh (host/mesh/mesh_read.cpp): the shipped meshes read as their
// SOURCE.md documents them, one mesh written in every supported format reads back identical,
// dispatch errors name the file, and no garbage makes the readers crash or hang.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "host/common/input_error.h"
#include "host/mesh/mesh.h"
#include "host/mesh/mesh_formats.h"
#include "tests/mesh/mesh_test_support.h"

namespace sigmafem {
namespace {

using test::TempDir;

// SOURCE.md quotes volumes to 4 significant digits and coordinates to 6.
constexpr double kQuotedVolumeTolerance = 5e-3;
constexpr double kQuotedCoordinateTolerance = 1e-5;

double total_volume(const Mesh& mesh) {
  double sum = 0.0;
  for (int e = 0; e < mesh.tetrahedron_count(); ++e) sum += tetrahedron_volume(mesh, e);
  return sum;
}

int count_inverted(const Mesh& mesh) {
  int inverted = 0;
  for (int e = 0; e < mesh.tetrahedron_count(); ++e) inverted += tetrahedron_volume(mesh, e) < 0;
  return inverted;
}

Eigen::Vector3d lowest_corner(const Mesh& mesh) {
  Eigen::Vector3d low = mesh.nodes[0];
  for (const auto& x : mesh.nodes) low = low.cwiseMin(x);
  return low;
}
Eigen::Vector3d highest_corner(const Mesh& mesh) {
  Eigen::Vector3d high = mesh.nodes[0];
  for (const auto& x : mesh.nodes) high = high.cwiseMax(x);
  return high;
}

void expect_same_mesh(const Mesh& expected, const Mesh& actual, const std::string& format,
                      double coordinate_tolerance = 0.0) {
  ASSERT_EQ(expected.node_count(), actual.node_count()) << format << ": node count";
  ASSERT_EQ(expected.tetrahedron_count(), actual.tetrahedron_count()) << format << ": tet count";
  for (int i = 0; i < expected.node_count(); ++i) {
    ASSERT_LE((expected.nodes[i] - actual.nodes[i]).cwiseAbs().maxCoeff(),
              coordinate_tolerance * expected.nodes[i].cwiseAbs().maxCoeff())
        << format << ": node " << i << " is " << actual.nodes[i].transpose() << ", expected "
        << expected.nodes[i].transpose();
  }
  for (int e = 0; e < expected.tetrahedron_count(); ++e) {
    ASSERT_EQ(expected.tetrahedra[e], actual.tetrahedra[e]) << format << ": tetrahedron " << e;
  }
}

TEST(ReadMesh, LiverMshMatchesSourceMd) {
  const Mesh mesh = read_mesh(test::liver_msh());
  EXPECT_EQ(mesh.node_count(), 181);
  EXPECT_EQ(mesh.tetrahedron_count(), 596);
  EXPECT_EQ(count_inverted(mesh), 0) << "SOURCE.md: all 596 tets are positively oriented";
  EXPECT_NEAR(total_volume(mesh), 36.56, kQuotedVolumeTolerance);
  EXPECT_TRUE(lowest_corner(mesh).isApprox(Eigen::Vector3d(-4.67928, 0.217888, -1.69285),
                                           kQuotedCoordinateTolerance));
  EXPECT_TRUE(highest_corner(mesh).isApprox(Eigen::Vector3d(1.80331, 5.15717, 2.72858),
                                            kQuotedCoordinateTolerance));
  // SOURCE.md: SOFA's 0-based indices 3, 39, 64 are Gmsh ids 4, 40, 65 at these points.
  EXPECT_TRUE(mesh.nodes[3].isApprox(Eigen::Vector3d(-0.642848, 2.34542, 2.57241), 1e-6));
  EXPECT_TRUE(mesh.nodes[39].isApprox(Eigen::Vector3d(-4.04515, 0.588905, 2.04346), 1e-6));
  EXPECT_TRUE(mesh.nodes[64].isApprox(Eigen::Vector3d(-2.95917, 1.94032, -1.64751), 1e-6));
}

TEST(ReadMesh, Liver2MapsNonContiguousIdsAndIgnoresTrianglesAndLines) {
  const Mesh mesh = read_mesh(test::liver2_msh());
  EXPECT_EQ(mesh.node_count(), 507);
  EXPECT_EQ(mesh.tetrahedron_count(), 1493) << "860 triangles and 71 lines must be ignored";
  // Mapping by line instead of by id would scramble the elements: inverted and flat ones,
  // and a wrong total volume.
  EXPECT_EQ(count_inverted(mesh), 0);
  EXPECT_NEAR(total_volume(mesh), 1.125, kQuotedVolumeTolerance);
  // The first node line is "2 0.3708951229648599 -0.4656592203247305 -0.1604279814553062".
  EXPECT_EQ(mesh.nodes[0],
            Eigen::Vector3d(0.3708951229648599, -0.4656592203247305, -0.1604279814553062));
  EXPECT_TRUE(lowest_corner(mesh).isApprox(Eigen::Vector3d(-1.20115, -0.53289, -0.84950),
                                           kQuotedCoordinateTolerance));
  EXPECT_TRUE(highest_corner(mesh).isApprox(Eigen::Vector3d(0.94300, 0.63344, 0.45915),
                                            kQuotedCoordinateTolerance));
}

TEST(ReadMesh, BoxMshIsTheDocumentedBox) {
  const Mesh mesh = read_mesh(test::box_msh());
  EXPECT_EQ(mesh.node_count(), 403);
  EXPECT_EQ(mesh.tetrahedron_count(), 1344);
  EXPECT_NEAR(std::abs(total_volume(mesh)), 0.30 * 0.15 * 0.15, 1e-12);
  EXPECT_TRUE(lowest_corner(mesh).isZero(1e-15));
  EXPECT_TRUE(highest_corner(mesh).isApprox(Eigen::Vector3d(0.30, 0.15, 0.15), 1e-15));
}

// One mesh through every writer and reader: the nodes (exactly, 17 digits) and the
// tetrahedra (same nodes in the same order) must come back unchanged.
TEST(ReadMesh, EveryFormatGivesTheSameMesh) {
  const Mesh box = read_mesh(test::box_msh());
  TempDir dir;
  expect_same_mesh(box, read_mesh(dir.write("box10.msh", test::gmsh10_text(box))), "Gmsh 1.0");
  expect_same_mesh(box, read_mesh(dir.write("box22.msh", test::gmsh22_text(box))), "Gmsh 2.2");
  expect_same_mesh(box, read_mesh(dir.write("box41.msh", test::gmsh41_text(box))), "Gmsh 4.1");
  expect_same_mesh(box, read_mesh(dir.write("ascii.vtk", test::vtk_ascii_text(box))), "VTK ASCII");
  expect_same_mesh(box, read_mesh(dir.write("binary.vtk", test::vtk_binary_text(box))),
                   "VTK BINARY double");
  // float points: equal to single precision, i.e. 2^-24 relative.
  expect_same_mesh(box, read_mesh(dir.write("float.vtk", test::vtk_binary_text(box, false))),
                   "VTK BINARY float", 6e-8);
  expect_same_mesh(box, read_mesh(dir.write("a51.vtk", test::vtk51_text(box, false))),
                   "VTK 5.1 ASCII");
  expect_same_mesh(box, read_mesh(dir.write("b51.vtk", test::vtk51_text(box, true))),
                   "VTK 5.1 BINARY");
}

TEST(ReadMesh, ChoosesTheReaderByContentNotByExtension) {
  const Mesh liver = read_mesh(test::liver_msh());
  TempDir dir;
  expect_same_mesh(liver, read_mesh(dir.write("liver.vtk", test::gmsh41_text(liver))),
                   "Gmsh 4.1 named .vtk");
  expect_same_mesh(liver, read_mesh(dir.write("liver.txt", test::vtk_ascii_text(liver))),
                   "VTK named .txt");
  // Leading blank lines and a UTF-8 byte order mark are tolerated before a Gmsh header.
  expect_same_mesh(liver,
                   read_mesh(dir.write("bom.msh", "\xEF\xBB\xBF\n\n" + test::gmsh22_text(liver))),
                   "Gmsh 2.2 after a BOM and blank lines");
}

TEST(ReadMesh, MissingFileIsAnInputErrorNamingIt) {
  TempDir dir;
  const std::string path = dir.file("no-such-mesh.msh");
  try {
    read_mesh(path);
    FAIL() << "reading a missing file should throw";
  } catch (const InputError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("mesh " + path + ": file not found"), std::string::npos) << message;
  }
}

TEST(ReadMesh, DirectoryIsAnInputError) {
  TempDir dir;
  try {
    read_mesh(dir.path());
    FAIL() << "reading a directory should throw";
  } catch (const InputError& error) {
    EXPECT_NE(std::string(error.what()).find("is a folder"), std::string::npos) << error.what();
  }
}

TEST(ReadMesh, UnrecognisedContentSaysWhatWasExpected) {
  for (const auto& [name, content, expected] : std::vector<std::array<std::string, 3>>{
           {"empty.msh", "", "the file is empty"},
           {"blank.msh", " \n\r\n\t\n", "the file is empty"},
           {"mesh.obj", "v 0 0 0\nv 1 0 0\n", "expected Gmsh ($MeshFormat or $NOD) or legacy VTK"},
           {"mesh.vtu", "<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\">",
            "XML VTK files (.vtu) are not supported"},
           {"noise.msh", std::string("\x01\x02\xff\xfe binary", 11), "\"???? binary\""},
       }) {
    const std::string message = test::read_error(name, content);
    EXPECT_NE(message.find("mesh "), std::string::npos) << message;
    EXPECT_NE(message.find(name), std::string::npos) << "the message names the file: " << message;
    EXPECT_NE(message.find(expected), std::string::npos) << name << ": " << message;
  }
}

TEST(TransformMesh, ScaleThenTranslateGivesTheMetricLiver) {
  // SOURCE.md: x_m = 0.033 x + (0.247453505, 0.111311543, 0.332910455) is Optimus's metric
  // liver, 0.214 x 0.163 x 0.146 m, volume 1.31e-3 m^3.
  Mesh mesh = read_mesh(test::liver_msh());
  const Eigen::Vector3d first = mesh.nodes[0];
  const Eigen::Vector3d translate(0.247453505, 0.111311543, 0.332910455);
  transform_mesh(mesh, 0.033, translate);
  EXPECT_TRUE(mesh.nodes[0].isApprox(0.033 * first + translate, 1e-15));
  const Eigen::Vector3d extent = highest_corner(mesh) - lowest_corner(mesh);
  EXPECT_NEAR(extent.x(), 0.214, 5e-4);
  EXPECT_NEAR(extent.y(), 0.163, 5e-4);
  EXPECT_NEAR(extent.z(), 0.146, 5e-4);
  EXPECT_NEAR(total_volume(mesh), 1.31e-3, 5e-6);
}

TEST(TransformMesh, RejectsANonPositiveOrNonFiniteScale) {
  Mesh mesh = read_mesh(test::box_msh());
  const Mesh before = mesh;
  for (const double scale : {0.0, -1.0, std::nan(""), HUGE_VAL}) {
    EXPECT_THROW(transform_mesh(mesh, scale, Eigen::Vector3d::Zero()), InputError) << scale;
  }
  EXPECT_THROW(transform_mesh(mesh, 1.0, Eigen::Vector3d(0.0, std::nan(""), 0.0)), InputError);
  EXPECT_EQ(mesh.nodes, before.nodes) << "a rejected transform leaves the mesh unchanged";
}

// Robustness: every prefix of a valid file and random byte corruptions must either read or
// throw InputError; anything else (a crash, another exception, a hang) fails. Under ASan and
// UBSan this also checks that no reader reads out of bounds on a truncated binary block.
// The readers are called on the text directly (mesh_formats.h): thousands of variants, no
// thousands of temporary files.
TEST(ReadMesh, TruncatedAndCorruptedFilesNeverCrash) {
  Mesh small;
  small.nodes = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  small.tetrahedra = {{0, 1, 2, 3}, {1, 2, 3, 4}};
  using Reader = Mesh (*)(std::string_view, const std::string&);
  const std::vector<std::tuple<std::string, std::string, Reader>> files = {
      {"t10.msh", test::gmsh10_text(small), &read_gmsh},
      {"t22.msh", test::gmsh22_text(small), &read_gmsh},
      {"t41.msh", test::gmsh41_text(small), &read_gmsh},
      {"ta.vtk", test::vtk_ascii_text(small), &read_vtk},
      {"tb.vtk", test::vtk_binary_text(small), &read_vtk},
      {"t51a.vtk", test::vtk51_text(small, false), &read_vtk},
      {"t51b.vtk", test::vtk51_text(small, true), &read_vtk},
  };
  std::mt19937 random(12345);
  static const char kGarbage[] = "$ \n\r-+.e9x\x00\xff#0123456789";
  const std::string garbage(kGarbage, sizeof kGarbage - 1);  // keeps the NUL byte
  int rejected = 0;
  for (const auto& [name, text, reader] : files) {
    ASSERT_EQ(reader(text, name).tetrahedron_count(), 2) << name << " as written";
    std::vector<std::string> variants;
    for (std::size_t length = 0; length < text.size(); ++length) {
      variants.push_back(text.substr(0, length));
    }
    for (int trial = 0; trial < 300; ++trial) {
      std::string corrupt = text;
      const int changes = 1 + trial % 3;
      for (int c = 0; c < changes; ++c) {
        corrupt[random() % corrupt.size()] = garbage[random() % garbage.size()];
      }
      variants.push_back(corrupt);
    }
    for (std::size_t v = 0; v < variants.size(); ++v) {
      // A copy sized exactly to the variant, so ASan sees any read past its end.
      const std::unique_ptr<char[]> exact(new char[variants[v].size() + 1]);
      std::copy(variants[v].begin(), variants[v].end(), exact.get());
      const std::string_view view(exact.get(), variants[v].size());
      try {
        reader(view, name);
      } catch (const InputError& error) {
        ++rejected;
        ASSERT_EQ(std::string(error.what()).rfind("mesh " + name + ": ", 0), 0u)
            << name << " variant " << v << ": the message must name the file: " << error.what();
      } catch (const std::exception& error) {
        FAIL() << name << " variant " << v << ": expected InputError, got " << error.what();
      }
    }
  }
  EXPECT_GT(rejected, 0);
}

}  // namespace
}  // namespace sigmafem
