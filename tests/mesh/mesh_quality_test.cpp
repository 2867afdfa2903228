// tetrahedron_volume and orient_and_check (host/mesh/mesh_quality.cpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "host/common/input_error.h"
#include "host/mesh/mesh.h"
#include "mesh/unit_tetrahedron.h"
#include "tests/mesh/mesh_test_support.h"

namespace sigmafem {
namespace {

// A regular tetrahedron: volume / (mean edge)^3 = 1 / (6 sqrt 2).
const double kRegularQuality = 1.0 / (6.0 * std::sqrt(2.0));

std::string check_error(Mesh& mesh, const std::string& source) {
  try {
    orient_and_check(mesh, source);
  } catch (const InputError& error) {
    return error.what();
  }
  ADD_FAILURE() << "orient_and_check should have thrown";
  return {};
}

TEST(TetrahedronVolume, IsSignedBySixOfTheTripleProduct) {
  Mesh mesh = unit_tetrahedron();
  EXPECT_DOUBLE_EQ(tetrahedron_volume(mesh, 0), 1.0 / 6.0);
  std::swap(mesh.tetrahedra[0][0], mesh.tetrahedra[0][1]);
  EXPECT_DOUBLE_EQ(tetrahedron_volume(mesh, 0), -1.0 / 6.0);
}

TEST(OrientAndCheck, RegularTetrahedronHasTheRegularQuality) {
  Mesh mesh;
  const double a = 0.01;  // 1 cm edge: small in metres, still perfectly shaped
  mesh.nodes = {{a, a, a}, {a, -a, -a}, {-a, a, -a}, {-a, -a, a}};
  mesh.tetrahedra = {{0, 1, 2, 3}};
  const double edge = 2.0 * std::sqrt(2.0) * a;
  const MeshQualityReport report = orient_and_check(mesh, "regular");
  EXPECT_NEAR(report.min_quality, kRegularQuality, 1e-15);
  EXPECT_NEAR(report.total_volume, edge * edge * edge * kRegularQuality, 1e-18);
}

TEST(OrientAndCheck, LiverIsValidAsShipped) {
  Mesh mesh = read_mesh(test::liver_msh());
  const Mesh before = mesh;
  const MeshQualityReport report = orient_and_check(mesh, "liver.msh");
  EXPECT_EQ(report.inverted_reordered, 0);
  EXPECT_NEAR(report.total_volume, 36.56, 5e-3);
  EXPECT_GT(report.min_quality, 0.0);
  EXPECT_LT(report.min_quality, kRegularQuality);
  EXPECT_EQ(mesh.tetrahedra, before.tetrahedra) << "a valid mesh is left as it is";
}

TEST(OrientAndCheck, InvertedTetrahedraAreReorderedAndCounted) {
  const Mesh original = read_mesh(test::liver_msh());
  Mesh mesh = original;
  int inverted = 0;
  for (int e = 0; e < mesh.tetrahedron_count(); e += 7) {
    std::swap(mesh.tetrahedra[e][0], mesh.tetrahedra[e][1]);
    ++inverted;
  }
  const MeshQualityReport report = orient_and_check(mesh, "liver.msh");
  EXPECT_EQ(report.inverted_reordered, inverted);
  EXPECT_NEAR(report.total_volume, 36.56, 5e-3);
  for (int e = 0; e < mesh.tetrahedron_count(); ++e) {
    EXPECT_NEAR(tetrahedron_volume(mesh, e), tetrahedron_volume(original, e), 1e-15)
        << "tetrahedron " << e << " must be positive with its volume unchanged";
    if (e % 7 != 0) {
      EXPECT_EQ(mesh.tetrahedra[e], original.tetrahedra[e]) << "tetrahedron " << e;
    } else {
      auto nodes = mesh.tetrahedra[e];
      auto expected = original.tetrahedra[e];
      std::sort(nodes.begin(), nodes.end());
      std::sort(expected.begin(), expected.end());
      EXPECT_EQ(nodes, expected) << "tetrahedron " << e << " keeps its nodes";
    }
  }
  EXPECT_EQ(orient_and_check(mesh, "liver.msh").inverted_reordered, 0) << "idempotent";
}

TEST(OrientAndCheck, FlatTetrahedronIsRejectedByIndexAndNodes) {
  Mesh mesh = read_mesh(test::liver_msh());
  // A fourth corner in the plane of the first three: the centroid of a face of tet 0.
  const auto& t = mesh.tetrahedra[0];
  mesh.nodes.push_back((mesh.nodes[t[0]] + mesh.nodes[t[1]] + mesh.nodes[t[2]]) / 3.0);
  mesh.tetrahedra.push_back({t[0], t[1], t[2], 181});
  std::swap(mesh.tetrahedra[5][0], mesh.tetrahedra[5][1]);  // also one inverted element
  const Mesh before = mesh;
  const std::string message = check_error(mesh, "liver.msh");
  const std::string expected = "mesh liver.msh: tetrahedron 596 (nodes " + std::to_string(t[0]) +
                               " " + std::to_string(t[1]) + " " + std::to_string(t[2]) +
                               " 181) is degenerate: volume ";
  EXPECT_EQ(message.rfind(expected, 0), 0u) << message;
  EXPECT_NE(message.find(" m^3"), std::string::npos) << message;
  EXPECT_NE(message.find("Degenerate tetrahedra in all: 1 "), std::string::npos) << message;
  EXPECT_EQ(mesh.tetrahedra, before.tetrahedra)
      << "a failed check leaves the mesh as it was (the inverted one not yet fixed)";
}

TEST(OrientAndCheck, CountsEveryDegenerateElementAndCatchesCoincidentCorners) {
  Mesh mesh = unit_tetrahedron();
  mesh.nodes.push_back({0.5, 0.5, 0.0});  // in the z = 0 plane of nodes 0, 1, 2
  mesh.tetrahedra.push_back({0, 1, 2, 4});
  mesh.tetrahedra.push_back({3, 3, 3, 3});  // all corners the same point: 0 / 0 quality
  const std::string message = check_error(mesh, "box.msh");
  EXPECT_NE(message.find("tetrahedron 1 (nodes 0 1 2 4) is degenerate"), std::string::npos)
      << message;
  EXPECT_NE(message.find("Degenerate tetrahedra in all: 2 "), std::string::npos) << message;
}

TEST(OrientAndCheck, DegeneracyIsRelativeToElementSize) {
  // The same mesh in metres and in micrometres: same quality, both accepted.
  Mesh metres = read_mesh(test::box_msh());
  Mesh tiny = metres;
  transform_mesh(tiny, 1e-6, Eigen::Vector3d::Zero());
  const MeshQualityReport a = orient_and_check(metres, "box.msh");
  const MeshQualityReport b = orient_and_check(tiny, "box.msh");
  EXPECT_NEAR(b.min_quality, a.min_quality, 1e-12 * a.min_quality);
  EXPECT_NEAR(a.total_volume, 0.30 * 0.15 * 0.15, 1e-12);
  // A sliver that is thin but real (height 1e-3 of its edges) is accepted, not judged flat.
  Mesh sliver = unit_tetrahedron();
  sliver.nodes[3] = {0.3, 0.3, 1e-3};
  EXPECT_NO_THROW(orient_and_check(sliver, "sliver"));
}

TEST(OrientAndCheck, NodeIndexOutOfRangeIsAnError) {
  Mesh mesh = unit_tetrahedron();
  mesh.tetrahedra[0][2] = 10;
  EXPECT_NE(check_error(mesh, "hand.msh")
                .find("mesh hand.msh: tetrahedron 0 refers to node 10, but the mesh has 4 nodes"),
            std::string::npos);
}

}  // namespace
}  // namespace sigmafem
