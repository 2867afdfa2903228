// Tests for `mesh.refine` in load_scenario() (host/scenario/scenario_load.cpp): the mesh is
// refined after it is read, scaled, translated and oriented, the file's nodes keep their
// indices and positions, selections see the refined mesh, and a level outside 0..3 is an
// InputError naming the field. Also the shipped higher-resolution scenarios
// (scenarios/liver_fine.json, scenarios/box_large.json), which use it.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "scenario_directory.h"
#include "temp_path.h"
#include "host/common/input_error.h"
#include "host/scenario/scenario.h"

namespace sigmafem {
namespace {

using test::TempDir;
using nlohmann::json;


// A scenario on box.msh (403 nodes, 1344 tetrahedra) with a selected ligament, a listed one,
// a selected control and listed observed nodes: both kinds of node set.
json box_scenario() {
  return json::parse(R"({
    "format": "sigmafem-scenario/1",
    "mesh": {"file": "box.msh", "scale": 2.0, "translate": [1.0, 0.0, -1.0]},
    "material": {"young_modulus": 5000, "poisson_ratio": 0.45, "density": 1000},
    "time": {"dt": 0.01, "steps": 10},
    "ligaments": [
      {"name": "middle", "select": {"near": [1.0, 0.15, -0.85], "radius": 0.06}, "stiffness": 300},
      {"name": "corner_b", "nodes": [19, 2, 15], "stiffness": 200}
    ],
    "control": {"select": {"near": [1.6, 0.15, -0.85], "radius": 0.064}, "stiffness": 10000,
                "trajectory": {"type": "linear", "velocity": [0.004, 0.002, 0.001]}},
    "observations": {"nodes": [304, 280, 290]}
  })");
}

class ScenarioRefineTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_.copy(kScenarios + "box.msh", "box.msh"); }

  Scenario load(const json& scenario) const {
    return load_scenario(dir_.write("case.json", scenario.dump(2)));
  }

  // The message load_scenario throws, or a test failure if it loads.
  std::string error_of(const json& scenario) const {
    try {
      load(scenario);
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "load_scenario accepted " << scenario["mesh"].dump();
    return "";
  }

  TempDir dir_;
};

TEST_F(ScenarioRefineTest, DefaultIsNoRefinement) {
  const Scenario s = load(box_scenario());
  EXPECT_EQ(s.mesh_spec.refine, 0);
  EXPECT_EQ(s.mesh.node_count(), 403);
  EXPECT_EQ(s.mesh.tetrahedron_count(), 1344);
}

TEST_F(ScenarioRefineTest, OneLevelMultipliesElementsByEightAndKeepsTheFileNodes) {
  const Scenario coarse = load(box_scenario());
  json j = box_scenario();
  j["mesh"]["refine"] = 1;
  const Scenario fine = load(j);
  EXPECT_EQ(fine.mesh_spec.refine, 1);
  EXPECT_EQ(fine.mesh.tetrahedron_count(), 8 * coarse.mesh.tetrahedron_count());
  EXPECT_GT(fine.mesh.node_count(), coarse.mesh.node_count());
  // Refined after scale and translate: the file's nodes are where the coarse load put them.
  for (int i = 0; i < coarse.mesh.node_count(); ++i) {
    EXPECT_EQ(fine.mesh.nodes[static_cast<size_t>(i)], coarse.mesh.nodes[static_cast<size_t>(i)])
        << "node " << i;
  }
  EXPECT_NEAR(fine.mesh_report.total_volume, coarse.mesh_report.total_volume, 1e-12);
  EXPECT_GT(fine.mesh_report.min_quality, 0.0);
  // Listed nodes are the file's nodes; selections are made on the refined mesh, so they
  // keep every node they had and gain midpoints.
  EXPECT_EQ(fine.ligaments[1].nodes, coarse.ligaments[1].nodes);
  EXPECT_EQ(fine.observations.nodes, coarse.observations.nodes);
  for (const auto& [fine_nodes, coarse_nodes] :
       {std::pair{fine.ligaments[0].nodes, coarse.ligaments[0].nodes},
        std::pair{fine.control.nodes, coarse.control.nodes}}) {
    EXPECT_GT(fine_nodes.size(), coarse_nodes.size());
    const std::set<int> fine_set(fine_nodes.begin(), fine_nodes.end());
    for (int node : coarse_nodes) EXPECT_EQ(fine_set.count(node), 1u) << "node " << node;
    EXPECT_GE(*fine_nodes.rbegin(), coarse.mesh.node_count()) << "a midpoint is selected";
  }
}

TEST_F(ScenarioRefineTest, TwoLevelsMultiplyElementsBySixtyFour) {
  json j = box_scenario();
  j["mesh"]["refine"] = 2;
  EXPECT_EQ(load(j).mesh.tetrahedron_count(), 64 * 1344);
  j["mesh"]["refine"] = 2.0;  // an integral number written as a float is an integer
  EXPECT_EQ(load(j).mesh.tetrahedron_count(), 64 * 1344);
}

TEST_F(ScenarioRefineTest, LevelOutsideZeroToThreeIsRejectedNamingTheField) {
  const std::vector<std::pair<json, std::vector<std::string>>> cases = {
      {4, {"must be an integer from 0 to 3", "found 4"}},
      {-1, {"must be an integer from 0 to 3", "found -1"}},
      {1.5, {"expected an integer", "1.5"}},
      {"1", {"expected an integer", "\"1\" (a string)"}},
      {true, {"expected an integer"}},
  };
  for (const auto& [level, fragments] : cases) {
    SCOPED_TRACE(level.dump());
    json j = box_scenario();
    j["mesh"]["refine"] = level;
    const std::string message = error_of(j);
    EXPECT_EQ(message.rfind("scenario " + dir_.file("case.json") + ": mesh.refine: ", 0), 0u)
        << message;
    for (const std::string& fragment : fragments) {
      EXPECT_NE(message.find(fragment), std::string::npos)
          << "expected \"" << fragment << "\" in: " << message;
    }
  }
}

// ---------------------------------------------------------------------------------------
// The shipped higher-resolution scenarios.

void expect_every_node_set_used(const Scenario& s) {
  ASSERT_EQ(s.ligaments.size(), 3u);
  for (const Ligament& ligament : s.ligaments) EXPECT_GE(ligament.nodes.size(), 1u) << ligament.name;
  EXPECT_GE(s.control.nodes.size(), 1u);
  EXPECT_EQ(s.observations.nodes.size(), 12u);
  ASSERT_TRUE(s.filter.has_value());
}

TEST(ShippedFineScenarioTest, LiverFineIsTheLiverRefinedTwice) {
  const Scenario fine = load_scenario(kScenarios + "liver_fine.json");
  const Scenario coarse = load_scenario(kScenarios + "liver.json");
  EXPECT_EQ(fine.name, "liver_fine");
  EXPECT_EQ(fine.mesh_spec.refine, 2);
  EXPECT_EQ(fine.mesh.tetrahedron_count(), 38144) << "596 x 64";
  EXPECT_NEAR(fine.mesh_report.total_volume, coarse.mesh_report.total_volume, 1e-12);
  expect_every_node_set_used(fine);
  // Every node set is the liver's own: the file's nodes keep their indices. The SO's nodes
  // are listed rather than selected, since the selection would catch midpoints too and move
  // so(0) away from the start of liver_trajectory.csv (a jump at t = 0).
  for (size_t i = 0; i < coarse.ligaments.size(); ++i) {
    EXPECT_EQ(fine.ligaments[i].nodes, coarse.ligaments[i].nodes) << coarse.ligaments[i].name;
  }
  EXPECT_EQ(fine.observations.nodes, coarse.observations.nodes);
  EXPECT_EQ(fine.control.nodes, coarse.control.nodes);
  EXPECT_EQ(fine.control.start, coarse.control.start);
  EXPECT_LT((fine.control.trajectory.position(0.0, fine.control.start) - fine.control.start)
                .lpNorm<Eigen::Infinity>(),
            5.1e-7);
  EXPECT_EQ(fine.ligament_stiffness_at(0.0), coarse.ligament_stiffness_at(0.0));
  EXPECT_EQ(fine.time.steps, coarse.time.steps);
  EXPECT_EQ(fine.control.trajectory.times, coarse.control.trajectory.times);
}

TEST(ShippedFineScenarioTest, BoxLargeHasOverAHundredThousandElements) {
  const Scenario s = load_scenario(kScenarios + "box_large.json");
  EXPECT_EQ(s.name, "box_large");
  EXPECT_EQ(s.mesh_spec.refine, 1);
  EXPECT_GE(s.mesh.tetrahedron_count(), 100000);
  EXPECT_NEAR(s.mesh_report.total_volume, 0.30 * 0.15 * 0.15, 1e-12);
  expect_every_node_set_used(s);
  // box.json's selections: the ligaments at the face x = 0, the SO at x = 0.3 (on this finer
  // mesh the spheres also catch nodes inside the box, up to their radius deep).
  for (const Ligament& ligament : s.ligaments) {
    for (int node : ligament.nodes) EXPECT_LE(s.mesh.nodes[static_cast<size_t>(node)].x(), 0.035);
  }
  for (int node : s.control.nodes) EXPECT_GE(s.mesh.nodes[static_cast<size_t>(node)].x(), 0.268);
  for (int node : s.observations.nodes) {
    EXPECT_EQ(s.mesh.nodes[static_cast<size_t>(node)].z(), 0.15) << "observed on the top face";
  }
}

}  // namespace
}  // namespace sigmafem
