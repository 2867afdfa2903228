// ObservedPoint and ObservedPoints (host/mesh/observed_points.h): a node observes itself bit
// for bit; a located point reproduces a linear field exactly; the device layout; bad nodes.
#include "host/mesh/observed_points.h"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <string>

#include "mesh/unit_tetrahedron.h"

namespace sigmafem {
namespace {

// A field of 3 numbers per node, linear in the rest position: a + B X.
Eigen::VectorXd linear_field(const Mesh& mesh, const Eigen::Vector3d& a, const Eigen::Matrix3d& B) {
  Eigen::VectorXd field(3 * mesh.node_count());
  for (int i = 0; i < mesh.node_count(); ++i) field.segment<3>(3 * i) = a + B * mesh.nodes[i];
  return field;
}

TEST(ObservedPointsTest, NodesObserveThemselvesBitForBit) {
  std::mt19937 random(3);
  std::normal_distribution<double> normal;
  Eigen::VectorXd field(30);
  for (Eigen::Index i = 0; i < field.size(); ++i) field[i] = normal(random) * 1e3;
  const ObservedPoints points(std::vector<int>{7, 0, 9});
  ASSERT_EQ(points.size(), 3u);
  EXPECT_EQ(points[0].of(field), Eigen::Vector3d(field.segment<3>(21)));
  EXPECT_EQ(points[1].of(field), Eigen::Vector3d(field.segment<3>(0)));
  EXPECT_EQ(points[2].of(field), Eigen::Vector3d(field.segment<3>(27)));
  EXPECT_EQ(points[0].nearest_node(), 7);
}

TEST(ObservedPointsTest, LocatedPointsInterpolateALinearFieldExactly) {
  const Mesh mesh = unit_tetrahedron();
  Eigen::Matrix3d B;
  B << 1.1, 0.2, -0.3, 0.05, 0.9, 0.1, -0.2, 0.3, 1.2;
  const Eigen::VectorXd field = linear_field(mesh, Eigen::Vector3d(0.5, -0.25, 2.0), B);
  const Eigen::Vector3d face_centre = (mesh.nodes[0] + mesh.nodes[1] + mesh.nodes[2]) / 3.0;
  const ObservedPoint on_face = ObservedPoint::at(mesh, locate_point(mesh, face_centre));
  EXPECT_LT((on_face.of(field) - (Eigen::Vector3d(0.5, -0.25, 2.0) + B * face_centre)).norm(), 1e-14);
  EXPECT_LT((on_face.at_rest(mesh) - face_centre).norm(), 1e-15);
  for (std::size_t c = 0; c < 4; ++c) {
    if (on_face.nodes[c] == 3) EXPECT_EQ(on_face.weights[c], 0.0) << "off the face: no weight";
    else EXPECT_NEAR(on_face.weights[c], 1.0 / 3.0, 1e-15);
  }
  const ObservedPoint on_node = ObservedPoint::at(mesh, locate_point(mesh, mesh.nodes[2]));
  EXPECT_EQ(on_node.nodes, (std::array<int, 4>{2, 2, 2, 2}));
  EXPECT_EQ(on_node.of(field), Eigen::Vector3d(field.segment<3>(6)));
}

TEST(ObservedPointsTest, DeviceLayoutIsFourCornersPerPoint) {
  ObservedPoints points(std::vector<int>{4});
  ObservedPoint p;
  p.nodes = {1, 2, 3, 5};
  p.weights = {0.1, 0.2, 0.3, 0.4};
  points.push_back(p);
  EXPECT_EQ(corner_nodes(points), (std::vector<int>{4, 4, 4, 4, 1, 2, 3, 5}));
  EXPECT_EQ(corner_weights(points), (std::vector<double>{1, 0, 0, 0, 0.1, 0.2, 0.3, 0.4}));
  EXPECT_EQ(corner_nodes(ObservedPoints()).size(), 4u) << "a device buffer cannot be empty";
}

TEST(ObservedPointsTest, ANodeOutsideTheMeshIsRefused) {
  const ObservedPoints points(std::vector<int>{0, 12});
  EXPECT_NO_THROW(check_observed_points(points, 13, "test"));
  try {
    check_observed_points(points, 12, "test");
    FAIL() << "accepted node 12 of 12";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("observed point 1 uses node 12"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sigmafem
