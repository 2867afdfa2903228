// Tests for node selection (host/scenario/node_selection.cpp): near + radius and box, both
// inclusive with a nanometre slack, results sorted.
#include <gtest/gtest.h>

#include "host/scenario/scenario.h"

namespace sigmafem {
namespace {

// Nodes on a line and one off it; no tetrahedra needed to select nodes.
Mesh five_nodes() {
  Mesh mesh;
  mesh.nodes = {Eigen::Vector3d(0.3, 0, 0), Eigen::Vector3d(0.0, 0, 0), Eigen::Vector3d(0.1, 0, 0),
                Eigen::Vector3d(0.2, 0, 0), Eigen::Vector3d(0.1, 0.1, 0.1)};
  return mesh;
}

TEST(NodeSelectionTest, NearPicksEveryNodeWithinTheRadiusSorted) {
  const Mesh mesh = five_nodes();
  EXPECT_EQ(select_nodes_near(mesh, Eigen::Vector3d(0.1, 0, 0), 0.15),
            (std::vector<int>{1, 2, 3, 4}));
  EXPECT_EQ(select_nodes_near(mesh, Eigen::Vector3d(0.1, 0, 0), 0.01), (std::vector<int>{2}));
}

TEST(NodeSelectionTest, NearIsInclusiveDespiteRounding) {
  Mesh mesh;
  mesh.nodes = {Eigen::Vector3d(1.1, 0, 0)};
  // 1.1 - 0.8 = 0.30000000000000004 in doubles: a node written 0.3 m away must still be in.
  ASSERT_GT(1.1 - 0.8, 0.3);
  EXPECT_EQ(select_nodes_near(mesh, Eigen::Vector3d(0.8, 0, 0), 0.3), (std::vector<int>{0}));
  EXPECT_TRUE(select_nodes_near(mesh, Eigen::Vector3d(0.8, 0, 0), 0.2999).empty());
  EXPECT_EQ(select_nodes_near(five_nodes(), Eigen::Vector3d(0.1, 0, 0), 0.1),
            (std::vector<int>{1, 2, 3}));
}

TEST(NodeSelectionTest, NearFarAwayIsEmpty) {
  EXPECT_TRUE(select_nodes_near(five_nodes(), Eigen::Vector3d(1, 1, 1), 0.1).empty());
}

TEST(NodeSelectionTest, BoxIsInclusiveOnItsFaces) {
  const Mesh mesh = five_nodes();
  EXPECT_EQ(select_nodes_in_box(mesh, Eigen::Vector3d(0.1, 0, 0), Eigen::Vector3d(0.2, 0, 0)),
            (std::vector<int>{2, 3}));
  EXPECT_EQ(select_nodes_in_box(mesh, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.3, 0.1, 0.1)),
            (std::vector<int>{0, 1, 2, 3, 4}));
}

TEST(NodeSelectionTest, BoxMissingEverythingIsEmpty) {
  EXPECT_TRUE(
      select_nodes_in_box(five_nodes(), Eigen::Vector3d(0.11, -1, -1), Eigen::Vector3d(0.19, 1, 1))
          .empty());
}

TEST(NodeSelectionTest, BoxFaceIsInclusiveDespiteRounding) {
  Mesh mesh;
  mesh.nodes = {Eigen::Vector3d(1.1 - 0.8, 0, 0)};  // 0.30000000000000004
  EXPECT_EQ(select_nodes_in_box(mesh, Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0.3, 0, 0)),
            (std::vector<int>{0}));
}

}  // namespace
}  // namespace sigmafem
