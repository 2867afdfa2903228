// candidate_regions (docs/FORMATS.md): listed regions load like ligaments' node sets; left
// out, the surface is split into kAutomaticRegionCount patches (host/scenario/surface_regions.h)
// that are disjoint, cover the free boundary nodes, leave the springs' nodes out, and are the
// same on every load; bad values are named.
#include <gtest/gtest.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <set>

#include "temp_path.h"
#include "host/common/input_error.h"
#include "host/scenario/scenario.h"
#include "host/scenario/surface_regions.h"

namespace sigmafem {
namespace {

using nlohmann::json;

class CandidateRegionsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_.copy(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.msh", "box.msh");
    scenario_ = json::parse(R"({
      "format": "sigmafem-scenario/1",
      "mesh": {"file": "box.msh"},
      "material": {"young_modulus": 5000, "poisson_ratio": 0.45, "density": 1000},
      "time": {"dt": 0.01, "steps": 10},
      "ligaments": [{"name": "corner_a", "select": {"near": [0, 0, 0], "radius": 0.035}, "stiffness": 150}],
      "control": {"select": {"near": [0.3, 0.075, 0.075], "radius": 0.032}, "stiffness": 10000,
                  "trajectory": {"type": "linear", "velocity": [0.004, 0.002, 0.001]}}
    })");
  }
  Scenario load(const json& scenario) const { return load_scenario(dir_.write("case.json", scenario.dump(2))); }
  std::string error_of(const json& scenario) const {
    try {
      load(scenario);
    } catch (const InputError& e) {
      return e.what();
    }
    return "(loaded)";
  }
  test::TempDir dir_;
  json scenario_;
};

TEST_F(CandidateRegionsTest, LeftOutTheSurfaceIsSplitIntoDisjointPatches) {
  const Scenario s = load(scenario_);
  ASSERT_EQ(static_cast<int>(s.candidate_regions.size()), kAutomaticRegionCount);
  std::set<int> held(s.control.nodes.begin(), s.control.nodes.end());
  held.insert(s.ligaments[0].nodes.begin(), s.ligaments[0].nodes.end());
  std::set<int> covered;
  for (std::size_t r = 0; r < s.candidate_regions.size(); ++r) {
    const Ligament& region = s.candidate_regions[r];
    EXPECT_EQ(region.name, "surface_" + std::to_string(r + 1));
    EXPECT_FALSE(region.nodes.empty());
    for (int node : region.nodes) {
      EXPECT_TRUE(covered.insert(node).second) << "node " << node << " in two regions";
      EXPECT_EQ(held.count(node), 0u) << "node " << node << " is a spring's";
    }
  }
  std::set<int> free_boundary;
  for (int node : boundary_nodes(s.mesh))
    if (!held.count(node)) free_boundary.insert(node);
  EXPECT_EQ(covered, free_boundary);
  // Deterministic: a region's name means the same nodes on every load.
  const Scenario again = load(scenario_);
  for (std::size_t r = 0; r < s.candidate_regions.size(); ++r)
    EXPECT_EQ(s.candidate_regions[r].nodes, again.candidate_regions[r].nodes);
  // Patches of nearby nodes: each region's nodes are closer to its own centre than the box's
  // half-diagonal (0.19 m).
  for (const Ligament& region : s.candidate_regions) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (int node : region.nodes) centre += s.mesh.nodes[static_cast<std::size_t>(node)] / region.nodes.size();
    for (int node : region.nodes) EXPECT_LT((s.mesh.nodes[static_cast<std::size_t>(node)] - centre).norm(), 0.19);
  }
}

TEST_F(CandidateRegionsTest, ListedOrCountedAsAsked) {
  json listed = scenario_;
  listed["candidate_regions"] = json::parse(R"([{"name": "bottom", "select": {"near": [0.15, 0.075, 0], "radius": 0.04}},
                                                {"name": "tip", "nodes": [3, 5]}])");
  const Scenario s = load(listed);
  ASSERT_EQ(s.candidate_regions.size(), 2u);
  EXPECT_EQ(s.candidate_regions[1].name, "tip");
  EXPECT_EQ(s.candidate_regions[1].nodes, (std::vector<int>{3, 5}));
  json counted = scenario_;
  counted["candidate_regions"] = {{"automatic", 3}};
  EXPECT_EQ(load(counted).candidate_regions.size(), 3u);
  counted["candidate_regions"] = {{"automatic", 0}};
  EXPECT_TRUE(load(counted).candidate_regions.empty());
}

TEST_F(CandidateRegionsTest, BadRegionsAreNamed) {
  json bad = scenario_;
  bad["candidate_regions"] = {{"automatic", -1}};
  EXPECT_NE(error_of(bad).find("candidate_regions.automatic: must be an integer from 0 to 64"), std::string::npos)
      << error_of(bad);
  bad["candidate_regions"] = json::parse(R"([{"name": "a:b", "nodes": [1]}])");
  EXPECT_NE(error_of(bad).find("candidate_regions[0].name: not a usable name"), std::string::npos) << error_of(bad);
  bad["candidate_regions"] = json::parse(R"([{"name": "a", "nodes": [1]}, {"name": "a", "nodes": [2]}])");
  EXPECT_NE(error_of(bad).find("candidate_regions[1].name: duplicate region name"), std::string::npos)
      << error_of(bad);
  bad["candidate_regions"] = json::parse(R"([{"name": "far", "select": {"near": [5, 5, 5], "radius": 0.01}}])");
  EXPECT_NE(error_of(bad).find("candidate_regions[0]: node set is empty"), std::string::npos) << error_of(bad);
  bad["candidate_regions"] = json::parse(R"([{"name": "a", "nodes": [1]}])");
  bad["effects"] = json::parse(R"([{"name": "extra_ligament:b", "value": 10}])");
  EXPECT_NE(error_of(bad).find("effects[0].name: no candidate region \"b\""), std::string::npos) << error_of(bad);
}

}  // namespace
}  // namespace sigmafem
