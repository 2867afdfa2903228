// A scenario's node sets resolved again on another mesh of the same organ (generate
// --truth-mesh): selections made again, listed nodes matched by position (an error naming the
// field and the node when there is none), automatic candidate regions at the same places.
#include "host/scenario/scenario_on_mesh.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "host/common/input_error.h"
#include "scenario_directory.h"
#include "temp_path.h"

namespace sigmafem {
namespace {


Mesh box_fine() {
  Mesh mesh = read_mesh(kScenarios + "box_fine.msh");
  orient_and_check(mesh, "box_fine.msh");
  return mesh;
}

Eigen::Vector3d centroid(const Mesh& mesh, const std::vector<int>& nodes) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int node : nodes) sum += mesh.nodes[node];
  return sum / static_cast<double>(nodes.size());
}

TEST(ScenarioOnMeshTest, SelectionsAreMadeAgainOnTheOtherMesh) {
  const Scenario box = load_scenario(kScenarios + "box.json");
  const Mesh fine = box_fine();
  const Scenario on_fine = scenario_on_mesh(box, fine, "--truth-mesh box_fine.msh");
  EXPECT_EQ(on_fine.mesh.node_count(), fine.node_count());
  ASSERT_EQ(on_fine.ligaments.size(), box.ligaments.size());
  for (std::size_t l = 0; l < box.ligaments.size(); ++l) {
    const NodeSetSpec& spec = box.ligaments[l].selection;
    ASSERT_EQ(spec.kind, NodeSetSpec::Kind::near) << "box.json selects its ligaments";
    EXPECT_EQ(on_fine.ligaments[l].nodes, select_nodes_near(fine, spec.near, spec.radius))
        << box.ligaments[l].name;
    EXPECT_GT(on_fine.ligaments[l].nodes.size(), box.ligaments[l].nodes.size())
        << "the finer mesh has more nodes in the same sphere";
    EXPECT_EQ(on_fine.ligaments[l].stiffness, box.ligaments[l].stiffness) << "the total is kept";
  }
  EXPECT_EQ(on_fine.control.nodes,
            select_nodes_near(fine, box.control.selection.near, box.control.selection.radius));
  EXPECT_EQ(on_fine.control.start, box.control.start)
      << "the same SO motion: so(0) stays the scenario's";
  EXPECT_TRUE(on_fine.observations.nodes.empty()) << "observed points are interpolated, not mapped";
}

TEST(ScenarioOnMeshTest, AutomaticRegionsKeepTheirNamesAndPlaces) {
  const Scenario box = load_scenario(kScenarios + "box.json");
  ASSERT_FALSE(box.candidate_regions.empty()) << "box.json gets automatic regions";
  const Scenario on_fine = scenario_on_mesh(box, box_fine(), "--truth-mesh box_fine.msh");
  ASSERT_EQ(on_fine.candidate_regions.size(), box.candidate_regions.size());
  const std::vector<int> surface = boundary_nodes(on_fine.mesh);
  for (std::size_t r = 0; r < box.candidate_regions.size(); ++r) {
    const Ligament& region = on_fine.candidate_regions[r];
    EXPECT_EQ(region.name, box.candidate_regions[r].name);
    ASSERT_FALSE(region.nodes.empty()) << region.name;
    for (int node : region.nodes)
      EXPECT_TRUE(std::binary_search(surface.begin(), surface.end(), node)) << "a surface node";
    EXPECT_LT((centroid(on_fine.mesh, region.nodes) - centroid(box.mesh, box.candidate_regions[r].nodes)).norm(),
              0.01)
        << region.name << " is the same patch of the surface on both meshes";
  }
}

class ScenarioOnMeshListTest : public ::testing::Test {
 protected:
  // box.json with its first ligament given as a node list of box.msh.
  Scenario load_with_listed(const std::vector<int>& nodes) {
    nlohmann::json scenario = nlohmann::json::parse(std::ifstream(kScenarios + "box.json"));
    scenario["mesh"]["file"] = kScenarios + "box.msh";
    scenario["ligaments"][0].erase("select");
    scenario["ligaments"][0]["nodes"] = nodes;
    return load_scenario(dir_.write("listed.json", scenario.dump(2)));
  }
  test::TempDir dir_{"sigmafem_scenario_on_mesh_test"};
};

TEST_F(ScenarioOnMeshListTest, ListedNodesAreMatchedByPosition) {
  // Nodes 0 to 7 are the box's corners in both files (Gmsh writes the geometry's points first).
  const Scenario box = load_with_listed({1, 3, 5});
  const Scenario on_fine = scenario_on_mesh(box, box_fine(), "--truth-mesh box_fine.msh");
  ASSERT_EQ(on_fine.ligaments[0].nodes.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k)
    EXPECT_LT((on_fine.mesh.nodes[on_fine.ligaments[0].nodes[k]] - box.mesh.nodes[box.ligaments[0].nodes[k]]).norm(),
              kCoincidentTolerance);
}

TEST_F(ScenarioOnMeshListTest, ListedNodeWithoutACoincidentNodeIsAnError) {
  // Node 8 of box.msh is at z = 0.03 on an edge; box_fine.msh has nodes every 0.0125 there.
  const Scenario box = load_with_listed({1, 8});
  try {
    scenario_on_mesh(box, box_fine(), "--truth-mesh box_fine.msh");
    FAIL() << "node 8 has no coincident node on box_fine.msh";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("--truth-mesh box_fine.msh"), std::string::npos) << message;
    EXPECT_NE(message.find("ligaments[0] \"corner_a\".nodes"), std::string::npos) << message;
    EXPECT_NE(message.find("node 8 "), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace sigmafem
