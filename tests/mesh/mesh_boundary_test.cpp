// boundary_faces and boundary_nodes (host/mesh/mesh_boundary.cpp).
#include <gtest/gtest.h>

#include <Eigen/Geometry>  // cross()
#include <algorithm>
#include <array>
#include <fstream>
#include <set>
#include <string>
#include <unordered_map>
#include <vector>

#include "host/mesh/mesh.h"
#include "mesh/unit_tetrahedron.h"
#include "tests/mesh/mesh_test_support.h"

namespace sigmafem {
namespace {

using Face = std::array<int, 3>;

Face sorted(Face f) {
  std::sort(f.begin(), f.end());
  return f;
}

std::set<Face> sorted_faces(const std::vector<Face>& faces) {
  std::set<Face> set;
  for (const Face& f : faces) set.insert(sorted(f));
  return set;
}

TEST(BoundaryFaces, OneTetrahedronHasFourOutwardFaces) {
  Mesh mesh = unit_tetrahedron();
  const std::vector<Face> faces = boundary_faces(mesh);
  ASSERT_EQ(faces.size(), 4u);
  test::expect_closed_outward_surface(mesh, faces, "one tetrahedron");
  EXPECT_EQ(boundary_nodes(mesh), (std::vector<int>{0, 1, 2, 3}));
  // Given inverted, the faces are still outward.
  std::swap(mesh.tetrahedra[0][1], mesh.tetrahedra[0][2]);
  test::expect_closed_outward_surface(mesh, boundary_faces(mesh), "one inverted tetrahedron");
}

TEST(BoundaryFaces, ASharedFaceIsInterior) {
  Mesh mesh = unit_tetrahedron();
  mesh.nodes.push_back({1, 1, 1});
  mesh.tetrahedra.push_back({1, 2, 3, 4});  // across face (1, 2, 3), positively oriented
  ASSERT_GT(tetrahedron_volume(mesh, 1), 0.0);
  const std::vector<Face> faces = boundary_faces(mesh);
  EXPECT_EQ(faces.size(), 6u);
  EXPECT_EQ(sorted_faces(faces).count({1, 2, 3}), 0u) << "the shared face is not boundary";
  test::expect_closed_outward_surface(mesh, faces, "two tetrahedra");
  EXPECT_EQ(boundary_nodes(mesh), (std::vector<int>{0, 1, 2, 3, 4}));
}

TEST(BoundaryFaces, LiverMatchesSourceMd) {
  const Mesh mesh = read_mesh(test::liver_msh());
  const std::vector<Face> faces = boundary_faces(mesh);
  EXPECT_EQ(faces.size(), 276u);
  EXPECT_EQ(boundary_nodes(mesh).size(), 140u) << "SOURCE.md: 41 of 181 nodes are interior";
  test::expect_closed_outward_surface(mesh, faces, "liver.msh");
  // SOURCE.md: the pocket at Gmsh node 140 (index 139) that liver.obj closes over.
  const std::set<Face> set = sorted_faces(faces);
  for (const Face& pocket : {Face{89, 92, 139}, Face{89, 93, 139}, Face{92, 93, 139}}) {
    EXPECT_EQ(set.count(pocket), 1u)
        << "pocket face " << pocket[0] << " " << pocket[1] << " " << pocket[2];
  }
  const std::vector<int> nodes = boundary_nodes(mesh);
  EXPECT_TRUE(std::is_sorted(nodes.begin(), nodes.end()));
  EXPECT_EQ(std::adjacent_find(nodes.begin(), nodes.end()), nodes.end()) << "unique";
}

// liver2.msh lists its boundary as 860 triangles (type 2). Read them with a separate, naive
// parser and compare with the faces computed from the tetrahedra.
TEST(BoundaryFaces, Liver2EqualsTheTrianglesOfTheFile) {
  const Mesh mesh = read_mesh(test::liver2_msh());
  std::ifstream in(test::liver2_msh());
  std::string word;
  int count = 0;
  in >> word >> count;
  ASSERT_EQ(word, "$NOD");
  std::unordered_map<int, int> index_of_id;
  for (int i = 0; i < count; ++i) {
    int id = 0;
    double x = 0, y = 0, z = 0;
    in >> id >> x >> y >> z;
    index_of_id[id] = i;
  }
  in >> word >> word >> count;
  ASSERT_EQ(word, "$ELM");
  std::set<Face> triangles;
  for (int e = 0; e < count; ++e) {
    int id = 0, type = 0, physical = 0, elementary = 0, n = 0;
    in >> id >> type >> physical >> elementary >> n;
    std::vector<int> nodes(n);
    for (int& node : nodes) in >> node;
    if (type == 2)
      triangles.insert(
          sorted({index_of_id.at(nodes[0]), index_of_id.at(nodes[1]), index_of_id.at(nodes[2])}));
  }
  ASSERT_TRUE(in.good());
  ASSERT_EQ(triangles.size(), 860u);

  const std::vector<Face> faces = boundary_faces(mesh);
  EXPECT_EQ(faces.size(), 860u);
  EXPECT_EQ(sorted_faces(faces), triangles);
  EXPECT_EQ(boundary_nodes(mesh).size(), 432u);
  test::expect_closed_outward_surface(mesh, faces, "liver2.msh");
}

// In the box every boundary face lies in one of the six planes and its normal is that
// plane's outward axis; the boundary nodes are exactly the nodes on the planes.
TEST(BoundaryFaces, BoxFacesLieOnTheBoxWithOutwardAxisNormals) {
  const Mesh mesh = read_mesh(test::box_msh());
  const Eigen::Vector3d size(0.30, 0.15, 0.15);
  constexpr double kOnPlane = 1e-12;
  const auto on_surface = [&](const Eigen::Vector3d& x) {
    return (x.array().abs() < kOnPlane).any() || ((x - size).array().abs() < kOnPlane).any();
  };
  const std::vector<Face> faces = boundary_faces(mesh);
  for (const Face& f : faces) {
    const Eigen::Vector3d& a = mesh.nodes[f[0]];
    const Eigen::Vector3d n = (mesh.nodes[f[1]] - a).cross(mesh.nodes[f[2]] - a).normalized();
    int axis = 0;
    n.cwiseAbs().maxCoeff(&axis);
    ASSERT_NEAR(std::abs(n[axis]), 1.0, 1e-9) << "face " << f[0] << " " << f[1] << " " << f[2];
    const double outward = a[axis] < 0.5 * size[axis] ? -1.0 : 1.0;
    EXPECT_EQ(n[axis] > 0 ? 1.0 : -1.0, outward)
        << "face " << f[0] << " " << f[1] << " " << f[2] << " points inward";
  }
  test::expect_closed_outward_surface(mesh, faces, "box.msh");
  std::vector<int> expected;
  for (int i = 0; i < mesh.node_count(); ++i) {
    if (on_surface(mesh.nodes[i])) expected.push_back(i);
  }
  EXPECT_EQ(boundary_nodes(mesh), expected);
}

}  // namespace
}  // namespace sigmafem
