// Tests for load_scenario() (host/scenario/scenario_load.cpp): the shipped scenarios and
// the SOFA reference scenario load with the expected contents; defaults, selections, paths
// and trajectories come out as docs/FORMATS.md says; and every kind of bad input throws an
// InputError "scenario FILE: FIELD: problem" naming the file and the field.
//
// Bad inputs are small edits of one valid scenario, written into a temporary folder beside
// a copy of scenarios/box.msh.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "host/common/input_error.h"
#include "host/engine/estimation_options.h"
#include "host/model/model.h"
#include "host/scenario/scenario.h"
#include "requirement.h"
#include "temp_path.h"

namespace sigmafem {
namespace {

namespace fs = std::filesystem;
using test::TempDir;
using nlohmann::json;

const std::string kSourceDir = SIGMAFEM_SOURCE_DIR;
const std::string kSharedDir = SIGMAFEM_SHARED_DIR;


// A valid scenario on box.msh using every section; the node counts below were read off
// the mesh (see box.json's description for the geometry).
json valid_scenario() {
  return json::parse(R"({
    "format": "sigmafem-scenario/1",
    "mesh": {"file": "box.msh"},
    "material": {"young_modulus": 5000, "poisson_ratio": 0.45, "density": 1000},
    "time": {"dt": 0.01, "steps": 100},
    "ligaments": [
      {"name": "corner_a", "select": {"near": [0, 0, 0], "radius": 0.035}, "stiffness": 150},
      {"name": "middle", "select": {"near": [0, 0.075, 0.075], "radius": 0.03}, "stiffness": 300},
      {"name": "corner_b", "nodes": [19, 2, 15], "stiffness": 200}
    ],
    "control": {"select": {"near": [0.3, 0.075, 0.075], "radius": 0.032}, "stiffness": 10000,
                "trajectory": {"type": "linear", "velocity": [0.004, 0.002, 0.001]}},
    "events": [{"time": 0.5, "ligament": "middle", "stiffness": 0.01}],
    "observations": {"nodes": [304, 280, 290], "noise_std": 0.0005},
    "filter": {"estimate": ["corner_a", "middle", "corner_b"],
               "initial_stiffness": [300, 600, 400], "observation_std": 0.0005}
  })");
}

class ScenarioLoadTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_.copy(kSourceDir + "/scenarios/box.msh", "box.msh"); }

  std::string write(const json& scenario, const std::string& name = "case.json") const {
    return dir_.write(name, scenario.dump(2));
  }

  // The message load_scenario(path) throws, or a test failure if it loads.
  static std::string error_of(const std::string& path) {
    try {
      load_scenario(path);
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "load_scenario accepted " << path;
    return "";
  }

  // Every message starts "scenario FILE: " and contains each fragment.
  static void expect_error(const std::string& path, const std::vector<std::string>& fragments) {
    const std::string message = error_of(path);
    EXPECT_EQ(message.rfind("scenario " + path + ": ", 0), 0u) << message;
    for (const std::string& fragment : fragments) {
      EXPECT_NE(message.find(fragment), std::string::npos)
          << "expected \"" << fragment << "\" in: " << message;
    }
  }

  TempDir dir_;
};

// ---------------------------------------------------------------------------------------
// What a valid file gives.

TEST_F(ScenarioLoadTest, ValidScenarioLoadsEverySection) {
  const Scenario s = load_scenario(write(valid_scenario()));
  EXPECT_EQ(s.format, "sigmafem-scenario/1");
  EXPECT_EQ(s.name, "case") << "the name defaults to the file stem";
  EXPECT_EQ(s.mesh_spec.resolved_path, dir_.file("box.msh"));
  EXPECT_EQ(s.mesh.node_count(), 403);
  EXPECT_EQ(s.mesh.tetrahedron_count(), 1344);
  EXPECT_NEAR(s.mesh_report.total_volume, 0.30 * 0.15 * 0.15, 1e-12);
  ASSERT_EQ(s.ligaments.size(), 3u);
  EXPECT_EQ(s.ligaments[0].nodes.size(), 7u);
  EXPECT_EQ(s.ligaments[1].nodes.size(), 5u);
  EXPECT_EQ(s.ligaments[2].nodes, (std::vector<int>{2, 15, 19})) << "listed nodes come sorted";
  EXPECT_EQ(s.control.nodes.size(), 8u);
  EXPECT_EQ(s.control.trajectory.type, Trajectory::Type::linear);
  ASSERT_EQ(s.events.size(), 1u);
  EXPECT_EQ(s.events[0].ligament, 1);
  EXPECT_EQ(s.events[0].ligament_name, "middle");
  EXPECT_EQ(s.observations.nodes, (std::vector<int>{304, 280, 290})) << "scenario order kept";
  ASSERT_TRUE(s.filter.has_value());
  EXPECT_EQ(s.filter->estimate, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(s.filter->initial_stiffness, (std::vector<double>{300, 600, 400}));
}

TEST_F(ScenarioLoadTest, OptionalFieldsTakeTheirDefaults) {
  json j = valid_scenario();
  for (const char* key : {"ligaments", "events", "observations", "filter"}) j.erase(key);
  const Scenario s = load_scenario(write(j, "minimal.json"));
  EXPECT_EQ(s.name, "minimal");
  EXPECT_EQ(s.description, "");
  EXPECT_EQ(s.mesh_spec.scale, 1.0);
  EXPECT_EQ(s.mesh_spec.translate, Eigen::Vector3d::Zero());
  EXPECT_EQ(s.damping.rayleigh_stiffness, 0.0);
  EXPECT_EQ(s.damping.rayleigh_mass, 0.0);
  EXPECT_EQ(s.gravity, Eigen::Vector3d::Zero());
  EXPECT_EQ(s.material.rotation, ElementRotation::qr) << "SOFA's large method, as the SOFA reference";
  EXPECT_EQ(s.solver.cg_max_iterations, 1000);
  EXPECT_EQ(s.solver.cg_tolerance, 1e-10);
  EXPECT_TRUE(s.ligaments.empty());
  EXPECT_TRUE(s.events.empty());
  EXPECT_TRUE(s.observations.nodes.empty());
  EXPECT_EQ(s.observations.noise_std, 0.0);
  EXPECT_FALSE(s.filter.has_value());
  EXPECT_EQ(s.output.vtk_every, 10);
}

TEST_F(ScenarioLoadTest, GivenOptionalFieldsAreRead) {
  json j = valid_scenario();
  j["name"] = "named";
  j["description"] = "free text";
  j["damping"] = {{"rayleigh_stiffness", 0.1}, {"rayleigh_mass", 0.2}};
  j["material"]["rotation"] = "polar";
  j["gravity"] = {0, -9.81, 0};
  j["solver"] = {{"cg_max_iterations", 300}, {"cg_tolerance", 1e-8}};
  j["output"] = {{"vtk_every", 0}};
  j["time"]["steps"] = 1.5e3;  // an integral number written as a float is an integer
  j["filter"]["initial_log_std"] = 0.5;
  j["filter"]["parameter_drift_log_std"] = 0.01;
  j["filter"]["sigma_points"] = "star";
  const Scenario s = load_scenario(write(j));
  EXPECT_EQ(s.name, "named");
  EXPECT_EQ(s.description, "free text");
  EXPECT_EQ(s.damping.rayleigh_stiffness, 0.1);
  EXPECT_EQ(s.damping.rayleigh_mass, 0.2);
  EXPECT_EQ(s.material.rotation, ElementRotation::polar);
  EXPECT_EQ(make_model(s).material.rotation, ElementRotation::polar) << "the model's elements use it";
  EXPECT_EQ(s.gravity, Eigen::Vector3d(0, -9.81, 0));
  EXPECT_EQ(s.solver.cg_max_iterations, 300);
  EXPECT_EQ(s.solver.cg_tolerance, 1e-8);
  EXPECT_EQ(s.output.vtk_every, 0);
  EXPECT_EQ(s.time.steps, 1500);
  EXPECT_EQ(s.filter->initial_log_std, 0.5);
  EXPECT_EQ(s.filter->parameter_drift_log_std, 0.01);
  EXPECT_EQ(s.filter->sigma_points, "star");
  EXPECT_FALSE(s.filter->adaptive_noise.enabled.has_value()) << "left out: the defaults";
  // Set, it reaches the filter's options.
  j["filter"]["adaptive_noise"] = {{"enabled", false}, {"window", 7}, {"false_alarm", 1e-3}};
  const EstimationOptions options = estimation_options(load_scenario(write(j, "adaptive.json")));
  EXPECT_FALSE(options.roukf.adaptive_noise.enabled);
  EXPECT_EQ(options.roukf.adaptive_noise.window, 7);
  EXPECT_EQ(options.roukf.adaptive_noise.false_alarm, 1e-3);
  j["filter"]["change_detection"] = {{"max_catch_up", 0}};
  EXPECT_EQ(estimation_options(load_scenario(write(j, "catch_up.json"))).detector.max_catch_up, 0);
}

// observations.points: each located on the mesh and observed as the material point there,
// after the nodes; a point on a node is that node; one a hair outside, the nearest point.
TEST_F(ScenarioLoadTest, ObservedPointsAreLocatedOnTheMeshAfterTheNodes) {
  json j = valid_scenario();
  const std::string plain = write(j, "plain.json");
  const Mesh& mesh = load_scenario(plain).mesh;
  const Eigen::Vector3d node = mesh.nodes[17];
  const Eigen::Vector3d inside(0.1234, 0.0567, 0.0891);
  const Eigen::Vector3d beside(0.3 + 1e-4, 0.075, 0.075);   // 0.1 mm past the face x = 0.3
  j["observations"]["points"] = {{node.x(), node.y(), node.z()},
                                 {inside.x(), inside.y(), inside.z()},
                                 {beside.x(), beside.y(), beside.z()}};
  const Scenario s = load_scenario(write(j));
  ASSERT_EQ(s.observations.nodes.size(), 3u);
  ASSERT_EQ(s.observations.points.size(), 3u);
  ASSERT_EQ(s.observations.observed.size(), 6u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(s.observations.observed[k].nodes[0], s.observations.nodes[k]);
    EXPECT_EQ(s.observations.observed[k].weights[0], 1.0);
  }
  const ObservedPoint& at_node = s.observations.observed[3];
  EXPECT_EQ(at_node.nodes, (std::array<int, 4>{17, 17, 17, 17}));
  EXPECT_EQ(at_node.weights, (std::array<double, 4>{1.0, 0.0, 0.0, 0.0}));
  const ObservedPoint& interior = s.observations.observed[4];
  EXPECT_LT((interior.at_rest(s.mesh) - inside).norm(), 1e-12);
  double sum = 0.0;
  for (double w : interior.weights) {
    EXPECT_GE(w, 0.0);
    sum += w;
  }
  EXPECT_NEAR(sum, 1.0, 1e-12);
  EXPECT_NEAR((s.observations.observed[5].at_rest(s.mesh) - beside).norm(), 1e-4, 1e-9)
      << "a point just outside is observed at the nearest point of the mesh";
  EXPECT_EQ(observed_point_name(s.observations, 1), "observations.nodes[1] (node 280)");
  EXPECT_EQ(observed_point_name(s.observations, 4), "observations.points[1]");
}

// observations.surface_cloud: its fields, the defaults for those left out, the view made a
// unit vector; no tracked points beside it.
TEST_F(ScenarioLoadTest, ASurfaceCloudReplacesTheTrackedPoints) {
  json j = valid_scenario();
  j["observations"].erase("nodes");
  j["observations"]["surface_cloud"] = {{"points_per_frame", 250}, {"view_direction", {0, 2, 0}}};
  const Scenario s = load_scenario(write(j));
  ASSERT_TRUE(s.observations.surface_cloud.has_value());
  EXPECT_EQ(s.observations.surface_cloud->points_per_frame, 250);
  EXPECT_EQ(s.observations.surface_cloud->view_direction, Eigen::Vector3d(0, 1, 0));
  EXPECT_NEAR(s.observations.surface_cloud->coverage, 1.0 / 3.0, 1e-15) << "left out: a third";
  EXPECT_TRUE(s.observations.observed.empty());
  ASSERT_TRUE(s.filter.has_value()) << "a cloud is what the filter observes";
}

TEST_F(ScenarioLoadTest, TheOutlierGateIsOffUnlessTheFilterAsks) {
  json j = valid_scenario();
  EXPECT_FALSE(estimation_options(load_scenario(write(j, "plain.json"))).roukf.outlier_gate.enabled);
  j["filter"]["outlier_gate"] = {{"enabled", true}, {"false_alarm", 1e-5}, {"max_share", 0.3}};
  const OutlierGateOptions gate = estimation_options(load_scenario(write(j))).roukf.outlier_gate;
  EXPECT_TRUE(gate.enabled);
  EXPECT_EQ(gate.false_alarm, 1e-5);
  EXPECT_EQ(gate.max_share, 0.3);
}

TEST_F(ScenarioLoadTest, ControlStartIsTheCentroidOfTheControlNodes) {
  const Scenario s = load_scenario(write(valid_scenario()));
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int node : s.control.nodes) sum += s.mesh.nodes[static_cast<size_t>(node)];
  EXPECT_NEAR((s.control.start - sum / 8.0).norm(), 0.0, 1e-15);
  EXPECT_NEAR(s.control.start.x(), 0.30, 1e-12) << "all control nodes are on the face x = 0.30";
  EXPECT_EQ(s.control.trajectory.position(0.0, s.control.start), s.control.start);
}

TEST_F(ScenarioLoadTest, EventsAreSortedByTimeKeepingFileOrderForTies) {
  json j = valid_scenario();
  j["events"] = json::parse(R"([
    {"time": 9, "ligament": "corner_a", "stiffness": 1},
    {"time": 2, "ligament": "corner_b", "stiffness": 2},
    {"time": 9, "ligament": "corner_a", "stiffness": 3},
    {"time": 0, "ligament": "middle", "stiffness": 4}])");
  const Scenario s = load_scenario(write(j));
  std::vector<double> order;
  for (const Event& e : s.events) order.push_back(e.stiffness);
  EXPECT_EQ(order, (std::vector<double>{4, 2, 1, 3}));
  EXPECT_EQ(s.ligament_stiffness_at(9.0), (std::vector<double>{3, 4, 2}));
  EXPECT_EQ(s.ligament_stiffness_at(1.0), (std::vector<double>{150, 4, 200}));
}

TEST_F(ScenarioLoadTest, SelectionsUseTheTransformedFrame) {
  json j = valid_scenario();
  j["mesh"]["scale"] = 2.0;
  j["mesh"]["translate"] = {1.0, 0.0, -1.0};
  // The corner (0, 0, 0) of the file is at (1, 0, -1) m; a box around it in metres.
  j["ligaments"][0]["select"] = {
      {"box", {{"min", {0.99, -0.01, -1.01}}, {"max", {1.01, 0.01, -0.99}}}}};
  // The face centres (0, 0.075, 0.075) and (0.3, 0.075, 0.075) of the file, in metres; the
  // radii are twice those of the valid scenario.
  j["ligaments"][1]["select"] = {{"near", {1.0, 0.15, -0.85}}, {"radius", 0.01}};
  j["control"]["select"] = {{"near", {1.6, 0.15, -0.85}}, {"radius", 0.064}};
  const Scenario s = load_scenario(write(j));
  EXPECT_EQ(s.ligaments[0].nodes, (std::vector<int>{1})) << "node 1 is the corner (0, 0, 0)";
  EXPECT_EQ(s.ligaments[1].nodes, (std::vector<int>{83})) << "node 83 is nearest the face centre";
  EXPECT_EQ(s.control.nodes.size(), 8u) << "the same nodes as radius 0.032 at scale 1";
  EXPECT_NEAR((s.mesh.nodes[1] - Eigen::Vector3d(1.0, 0.0, -1.0)).norm(), 0.0, 1e-15);
}

TEST_F(ScenarioLoadTest, PathsAreRelativeToTheScenarioFolder) {
  // The scenario in a subfolder, its mesh and trajectory beside it under other names.
  dir_.copy(kSourceDir + "/scenarios/box.msh", "sub/meshes/other.msh");
  dir_.write("sub/traj/path.csv", "time,x,y,z\n0,0.3,0.075,0.075\n2,0.32,0.075,0.075\n");
  json j = valid_scenario();
  j["mesh"]["file"] = "meshes/other.msh";
  j["control"]["trajectory"] = {{"type", "file"}, {"file", "traj/path.csv"}};
  const Scenario s = load_scenario(write(j, "sub/case.json"));
  EXPECT_EQ(s.mesh_spec.file, "meshes/other.msh");
  EXPECT_EQ(s.mesh_spec.resolved_path, dir_.file("sub/meshes/other.msh"));
  EXPECT_EQ(s.control.trajectory.type, Trajectory::Type::file);
  EXPECT_EQ(s.control.trajectory.file, "traj/path.csv") << "kept as written";
  EXPECT_EQ(s.control.trajectory.position(1.0, s.control.start),
            Eigen::Vector3d(0.31, 0.075, 0.075));
}

TEST_F(ScenarioLoadTest, WaypointTrajectoryIsRead) {
  json j = valid_scenario();
  j["control"]["trajectory"] = json::parse(R"({"type": "waypoints", "times": [0, 1, 3],
      "positions": [[0.3, 0.075, 0.075], [0.31, 0.075, 0.075], [0.31, 0.095, 0.075]]})");
  const Scenario s = load_scenario(write(j));
  const Trajectory& t = s.control.trajectory;
  EXPECT_EQ(t.type, Trajectory::Type::waypoints);
  EXPECT_EQ(t.times, (std::vector<double>{0, 1, 3}));
  EXPECT_EQ(t.position(1.0, s.control.start), Eigen::Vector3d(0.31, 0.075, 0.075));
  EXPECT_NEAR((t.position(2.0, s.control.start) - Eigen::Vector3d(0.31, 0.085, 0.075)).norm(), 0.0,
              1e-15);
  EXPECT_EQ(t.position(5.0, s.control.start), Eigen::Vector3d(0.31, 0.095, 0.075));
}

TEST_F(ScenarioLoadTest, DocumentedExampleLoads) {
  // The first ```json block of docs/FORMATS.md is the format's example: keep it valid.
  std::ifstream in(kSourceDir + "/docs/FORMATS.md");
  ASSERT_TRUE(in) << "docs/FORMATS.md not found";
  std::stringstream text;
  text << in.rdbuf();
  const std::string doc = text.str();
  const size_t begin = doc.find("```json\n");
  ASSERT_NE(begin, std::string::npos);
  const size_t end = doc.find("```", begin + 8);
  ASSERT_NE(end, std::string::npos);
  const Scenario s =
      load_scenario(dir_.write("example.json", doc.substr(begin + 8, end - begin - 8)));
  EXPECT_EQ(s.name, "box");
  EXPECT_EQ(s.ligaments.size(), 3u);
  EXPECT_EQ(s.solver.cg_max_iterations, 300);
  EXPECT_EQ(s.filter->estimate, (std::vector<int>{0, 2, 1}));
}

// ---------------------------------------------------------------------------------------
// Bad input: every case names the file and the field.

TEST_F(ScenarioLoadTest, MissingFileIsReported) {
  expect_error(dir_.file("nope.json"), {"not found"});
}

TEST_F(ScenarioLoadTest, InvalidJsonGivesTheLine) {
  const std::string path = dir_.write("broken.json",
                                      "{\n"
                                      "  \"format\": \"sigmafem-scenario/1\",\n"
                                      "  \"time\": {\"dt\": 0.01,, \"steps\": 3}\n"
                                      "}\n");
  expect_error(path, {"line 3, column 23", "invalid JSON", "syntax error"});
  expect_error(dir_.write("empty.json", ""), {"line 1", "invalid JSON"});
  expect_error(dir_.write("unterminated.json", "{\"format\": \"sigm\n\n"), {"invalid JSON"});
}

TEST_F(ScenarioLoadTest, TopLevelMustBeAnObject) {
  expect_error(dir_.write("array.json", "[1, 2]"), {"(top level)", "expected a JSON object"});
}

TEST_F(ScenarioLoadTest, DuplicateKeyIsReportedWithItsPath) {
  std::string text = valid_scenario().dump(2);
  // Repeat the stiffness of the second ligament: nlohmann alone would keep the last value.
  const std::string needle = "\"stiffness\": 300";
  const size_t at = text.find(needle);
  ASSERT_NE(at, std::string::npos);
  text.insert(at, "\"stiffness\": 301, ");
  expect_error(dir_.write("dup.json", text), {"ligaments[1].stiffness", "duplicate key"});
}

// One edit of the valid scenario, and what the message must contain.
struct BadCase {
  std::string label;
  std::function<void(json&)> edit;
  std::vector<std::string> expected;
};

TEST_F(ScenarioLoadTest, BadFieldsAreNamed) {
  const std::vector<BadCase> cases = {
      // format
      {"format missing", [](json& j) { j.erase("format"); }, {"format: missing required field"}},
      {"format wrong",
       [](json& j) { j["format"] = "sigmafem-scenario/2"; },
       {"format:", "sigmafem-scenario/1", "sigmafem-scenario/2"}},
      {"format not a string", [](json& j) { j["format"] = 1; }, {"format:", "expected a string"}},
      // unknown fields at every level, with a suggestion and the allowed list
      {"unknown top level",
       [](json& j) { j["meshh"] = j["mesh"]; },
       {"meshh: unknown field", "did you mean \"mesh\"", "allowed here: format, name"}},
      {"typo in ligament",
       [](json& j) {
         j["ligaments"][1]["stifness"] = 300;
         j["ligaments"][1].erase("stiffness");
       },
       {"ligaments[1] \"middle\".stifness: unknown field", "did you mean \"stiffness\"",
        "allowed here: name, nodes, select, stiffness"}},
      {"unknown in select",
       [](json& j) { j["ligaments"][0]["select"]["radios"] = 0.1; },
       {"ligaments[0] \"corner_a\".select.radios: unknown field", "did you mean \"radius\""}},
      {"unknown in material",
       [](json& j) { j["material"]["youngs_modulus"] = 1; },
       {"material.youngs_modulus: unknown field"}},
      {"unknown in mesh", [](json& j) { j["mesh"]["rotate"] = 1; }, {"mesh.rotate: unknown field"}},
      {"unknown in time", [](json& j) { j["time"]["t_end"] = 1; }, {"time.t_end: unknown field"}},
      {"unknown in solver",
       [](json& j) {
         j["solver"] = {{"cg_tol", 1e-8}};
       },
       {"solver.cg_tol: unknown field", "cg_tolerance"}},
      {"unknown in damping",
       [](json& j) {
         j["damping"] = {{"alpha", 0.1}};
       },
       {"damping.alpha: unknown field"}},
      {"unknown in control",
       [](json& j) { j["control"]["speed"] = 1; },
       {"control.speed: unknown field"}},
      {"field of another trajectory type",
       [](json& j) { j["control"]["trajectory"]["file"] = "x.csv"; },
       {"control.trajectory.file: unknown field", "allowed here: type, velocity"}},
      {"unknown in event",
       [](json& j) { j["events"][0]["when"] = 1; },
       {"events[0].when: unknown field"}},
      {"unknown in observations",
       [](json& j) { j["observations"]["noise"] = 1; },
       {"observations.noise: unknown field", "noise_std"}},
      {"unknown in filter",
       [](json& j) { j["filter"]["sigma_point"] = "star"; },
       {"filter.sigma_point: unknown field", "did you mean \"sigma_points\""}},
      {"adaptive noise window out of range",
       [](json& j) { j["filter"]["adaptive_noise"] = {{"window", 0}}; },
       {"filter.adaptive_noise.window", "1..1000"}},
      {"adaptive noise false alarm not a probability",
       [](json& j) { j["filter"]["adaptive_noise"] = {{"false_alarm", 0.7}}; },
       {"filter.adaptive_noise.false_alarm", "probability"}},
      {"adaptive noise enabled not a boolean",
       [](json& j) { j["filter"]["adaptive_noise"] = {{"enabled", "yes"}}; },
       {"filter.adaptive_noise.enabled", "expected true or false"}},
      {"negative catch-up",
       [](json& j) { j["filter"]["change_detection"] = {{"max_catch_up", -1}}; },
       {"filter.change_detection.max_catch_up", "must not be negative"}},
      {"change detection window out of range",
       [](json& j) { j["filter"]["change_detection"] = {{"window", 5000}}; },
       {"filter.change_detection.window", "1..1000"}},
      {"unknown in output",
       [](json& j) {
         j["output"] = {{"vtk", 1}};
       },
       {"output.vtk: unknown field"}},
      {"unknown in box",
       [](json& j) {
         j["ligaments"][0]["select"] = {
             {"box", {{"min", {0, 0, 0}}, {"max", {1, 1, 1}}, {"mid", 0}}}};
       },
       {"select.box.mid: unknown field"}},
      // wrong types
      {"steps a string",
       [](json& j) { j["time"]["steps"] = "1500"; },
       {"time.steps:", "expected an integer", "\"1500\" (a string)"}},
      {"steps fractional",
       [](json& j) { j["time"]["steps"] = 10.5; },
       {"time.steps:", "expected an integer"}},
      {"modulus a string",
       [](json& j) { j["material"]["young_modulus"] = "5000"; },
       {"material.young_modulus:", "expected a number"}},
      {"gravity two numbers",
       [](json& j) {
         j["gravity"] = {0, -9.81};
       },
       {"gravity:", "expected an array of 3 numbers"}},
      {"translate element a string",
       [](json& j) {
         j["mesh"]["translate"] = {0, "a", 0};
       },
       {"mesh.translate[1]:", "expected a number"}},
      {"material an array",
       [](json& j) {
         j["material"] = {1, 2};
       },
       {"material:", "expected an object"}},
      {"ligaments an object",
       [](json& j) {
         j["ligaments"] = {{"a", 1}};
       },
       {"ligaments:", "expected an array"}},
      {"ligament name a number",
       [](json& j) { j["ligaments"][0]["name"] = 3; },
       {"ligaments[0].name:", "expected a string"}},
      {"node index a float",
       [](json& j) {
         j["ligaments"][2]["nodes"] = {2, 15.5};
       },
       {"ligaments[2] \"corner_b\".nodes[1]:", "expected an integer"}},
      {"event time null",
       [](json& j) { j["events"][0]["time"] = nullptr; },
       {"events[0].time:", "expected a number, found null"}},
      {"filter a boolean", [](json& j) { j["filter"] = true; }, {"filter:", "expected an object"}},
      // missing required fields
      {"mesh missing", [](json& j) { j.erase("mesh"); }, {"mesh: missing required field"}},
      {"mesh file missing",
       [](json& j) { j["mesh"].erase("file"); },
       {"mesh.file: missing required field"}},
      {"material missing",
       [](json& j) { j.erase("material"); },
       {"material: missing required field"}},
      {"density missing",
       [](json& j) { j["material"].erase("density"); },
       {"material.density: missing required field"}},
      {"time missing", [](json& j) { j.erase("time"); }, {"time: missing required field"}},
      {"dt missing", [](json& j) { j["time"].erase("dt"); }, {"time.dt: missing required field"}},
      {"control missing", [](json& j) { j.erase("control"); }, {"control: missing required field"}},
      {"trajectory missing",
       [](json& j) { j["control"].erase("trajectory"); },
       {"control.trajectory: missing required field"}},
      {"velocity missing",
       [](json& j) { j["control"]["trajectory"].erase("velocity"); },
       {"control.trajectory.velocity: missing required field"}},
      {"ligament stiffness missing",
       [](json& j) { j["ligaments"][0].erase("stiffness"); },
       {"ligaments[0] \"corner_a\".stiffness: missing required field"}},
      {"observation_std missing",
       [](json& j) { j["filter"].erase("observation_std"); },
       {"filter.observation_std: missing required field"}},
      // mesh
      {"mesh file not there",
       [](json& j) { j["mesh"]["file"] = "meshes/liver.msh"; },
       {"mesh.file:", "file not found", "meshes/liver.msh"}},
      {"scale zero", [](json& j) { j["mesh"]["scale"] = 0; }, {"mesh.scale:", "must be > 0"}},
      // node sets
      {"node out of range",
       [](json& j) {
         j["ligaments"][2]["nodes"] = {2, 403};
       },
       {"ligaments[2] \"corner_b\".nodes[1]:", "node 403 does not exist", "403 nodes"}},
      {"node negative",
       [](json& j) { j["ligaments"][2]["nodes"] = {-1}; },
       {"ligaments[2] \"corner_b\".nodes[0]:", "node -1 does not exist"}},
      {"control node out of range",
       [](json& j) {
         j["control"].erase("select");
         j["control"]["nodes"] = {1000};
       },
       {"control.nodes[0]:", "node 1000 does not exist"}},
      {"observed node out of range",
       [](json& j) {
         j["observations"]["nodes"] = {1, 2, 99999};
       },
       {"observations.nodes[2]:", "node 99999 does not exist"}},
      {"node listed twice",
       [](json& j) {
         j["ligaments"][2]["nodes"] = {2, 15, 2};
       },
       {"ligaments[2] \"corner_b\".nodes[2]:", "listed twice"}},
      {"observed node twice",
       [](json& j) {
         j["observations"]["nodes"] = {304, 280, 304};
       },
       {"observations.nodes[2]:", "listed twice"}},
      {"empty near selection",
       [](json& j) {
         j["ligaments"][1]["select"] = {{"near", {0.10, 0.0, 0.07}}, {"radius", 0.002}};
       },
       {"ligaments[1] \"middle\": node set is empty (near [0.1, 0, 0.07], radius 0.002 m); enlarge "
        "radius or list nodes"}},
      {"empty box selection",
       [](json& j) {
         j["control"]["select"] = {{"box", {{"min", {0.5, 0.5, 0.5}}, {"max", {0.6, 0.6, 0.6}}}}};
       },
       {"control: node set is empty (box min [0.5, 0.5, 0.5], max [0.6, 0.6, 0.6] m)"}},
      {"empty node list",
       [](json& j) { j["ligaments"][2]["nodes"] = json::array(); },
       {"ligaments[2] \"corner_b\": node set is empty", "list at least one node"}},
      {"nodes and select",
       [](json& j) { j["ligaments"][0]["nodes"] = {1}; },
       {"ligaments[0] \"corner_a\":", "not both"}},
      {"neither nodes nor select",
       [](json& j) { j["ligaments"][0].erase("select"); },
       {"ligaments[0] \"corner_a\":", "missing node set"}},
      {"near without radius",
       [](json& j) { j["ligaments"][0]["select"].erase("radius"); },
       {"ligaments[0] \"corner_a\".select.radius: missing required field"}},
      {"near and box",
       [](json& j) {
         j["ligaments"][0]["select"]["box"] = {{"min", {0, 0, 0}}, {"max", {1, 1, 1}}};
       },
       {"select:", "not both"}},
      {"radius zero",
       [](json& j) { j["ligaments"][0]["select"]["radius"] = 0; },
       {"select.radius:", "must be > 0"}},
      {"box min above max",
       [](json& j) {
         j["ligaments"][0]["select"] = {{"box", {{"min", {0, 0.1, 0}}, {"max", {1, 0, 1}}}}};
       },
       {"select.box:", "exceeds max"}},
      // ligament names
      {"duplicate ligament names",
       [](json& j) { j["ligaments"][2]["name"] = "corner_a"; },
       {"ligaments[2] \"corner_a\".name:", "duplicate ligament name", "ligaments[0]"}},
      {"ligament name with a comma",
       [](json& j) { j["ligaments"][2]["name"] = "a,b"; },
       {"ligaments[2] \"a,b\".name:", "CSV column header"}},
      {"ligament name empty",
       [](json& j) { j["ligaments"][2]["name"] = ""; },
       {"ligaments[2] \"\".name:", "non-empty"}},
      // references to ligaments
      {"event on an unknown ligament",
       [](json& j) { j["events"][0]["ligament"] = "midle"; },
       {"events[0].ligament:", "no ligament named \"midle\"", "did you mean \"middle\"",
        "corner_a, middle, corner_b"}},
      {"filter estimates an unknown ligament",
       [](json& j) { j["filter"]["estimate"][1] = "falciform"; },
       {"filter.estimate[1]:", "no ligament named \"falciform\""}},
      {"filter estimates a ligament twice",
       [](json& j) { j["filter"]["estimate"][2] = "corner_a"; },
       {"filter.estimate[2]:", "listed twice"}},
      {"filter estimates nothing",
       [](json& j) {
         j["filter"]["estimate"] = json::array();
         j["filter"]["initial_stiffness"] = json::array();
       },
       {"filter.estimate:", "empty"}},
      {"filter prior length",
       [](json& j) {
         j["filter"]["initial_stiffness"] = {300, 600};
       },
       {"filter.initial_stiffness:", "2 values for 3"}},
      {"filter prior zero",
       [](json& j) { j["filter"]["initial_stiffness"][1] = 0; },
       {"filter.initial_stiffness[1]:", "must be > 0"}},
      {"filter unknown sigma points",
       [](json& j) { j["filter"]["sigma_points"] = "simplx"; },
       {"filter.sigma_points:", "did you mean \"simplex\""}},
      {"filter without observations",
       [](json& j) { j["observations"]["nodes"] = json::array(); },
       {"filter:", "needs observations", "surface_cloud"}},
      {"surface cloud beside tracked nodes",
       [](json& j) { j["observations"]["surface_cloud"] = json::object(); },
       {"observations.surface_cloud:", "either tracked points", "not both"}},
      {"surface cloud coverage zero",
       [](json& j) {
         j["observations"].erase("nodes");
         j["observations"]["surface_cloud"] = {{"coverage", 0}};
       },
       {"observations.surface_cloud.coverage:", "(0, 1]"}},
      {"surface cloud without a view",
       [](json& j) {
         j["observations"].erase("nodes");
         j["observations"]["surface_cloud"] = {{"view_direction", {0, 0, 0}}};
       },
       {"observations.surface_cloud.view_direction:", "must not be zero"}},
      {"surface cloud of no points",
       [](json& j) {
         j["observations"].erase("nodes");
         j["observations"]["surface_cloud"] = {{"points_per_frame", 0}};
       },
       {"observations.surface_cloud.points_per_frame:", "must be 1 to 1000000"}},
      {"surface cloud unknown field",
       [](json& j) {
         j["observations"].erase("nodes");
         j["observations"]["surface_cloud"] = {{"points", 300}};
       },
       {"observations.surface_cloud.points: unknown field", "points_per_frame"}},
      {"outlier gate share out of range",
       [](json& j) { j["filter"]["outlier_gate"] = {{"enabled", true}, {"max_share", 1.5}}; },
       {"filter.outlier_gate.max_share:", "in (0, 1)"}},
      {"outlier gate unknown field",
       [](json& j) { j["filter"]["outlier_gate"] = {{"window", 5}}; },
       {"filter.outlier_gate.window: unknown field"}},
      {"observed point outside the mesh",
       [](json& j) { j["observations"]["points"] = json::parse("[[0.1, 0.05, 0.05], [0.1, 0.05, 0.5]]"); },
       {"observations.points[1]:", "mm outside the mesh", "mesh.scale"}},
      {"observed point not a point",
       [](json& j) { j["observations"]["points"] = json::parse("[[0.1, 0.05]]"); },
       {"observations.points[0]:"}},
      {"observed points not a list",
       [](json& j) { j["observations"]["points"] = 0.1; },
       {"observations.points:"}},
      {"filter observation std zero",
       [](json& j) { j["filter"]["observation_std"] = 0; },
       {"filter.observation_std:", "must be > 0"}},
      {"filter negative drift",
       [](json& j) { j["filter"]["parameter_drift_log_std"] = -0.1; },
       {"filter.parameter_drift_log_std:", "must be >= 0"}},
      {"filter zero prior std",
       [](json& j) { j["filter"]["initial_log_std"] = 0; },
       {"filter.initial_log_std:", "must be > 0"}},
      // time and solver
      {"dt zero", [](json& j) { j["time"]["dt"] = 0; }, {"time.dt:", "must be > 0, found 0"}},
      {"dt negative",
       [](json& j) { j["time"]["dt"] = -0.01; },
       {"time.dt:", "must be > 0, found -0.01"}},
      {"steps zero",
       [](json& j) { j["time"]["steps"] = 0; },
       {"time.steps:", "must be 1 to 10000000, found 0"}},
      {"steps negative", [](json& j) { j["time"]["steps"] = -5; }, {"time.steps:", "must be 1 to 10000000, found -5"}},
      {"steps huge", [](json& j) { j["time"]["steps"] = 1e12; }, {"time.steps:", "out of range"}},
      {"cg iterations zero",
       [](json& j) {
         j["solver"] = {{"cg_max_iterations", 0}};
       },
       {"solver.cg_max_iterations:", "must be >= 1"}},
      {"cg tolerance zero",
       [](json& j) {
         j["solver"] = {{"cg_tolerance", 0}};
       },
       {"solver.cg_tolerance:", "(0, 1)"}},
      {"vtk_every negative",
       [](json& j) {
         j["output"] = {{"vtk_every", -1}};
       },
       {"output.vtk_every:", "must be >= 0"}},
      // material
      {"E zero",
       [](json& j) { j["material"]["young_modulus"] = 0; },
       {"material.young_modulus:", "must be > 0"}},
      {"E negative",
       [](json& j) { j["material"]["young_modulus"] = -5000; },
       {"material.young_modulus:", "must be > 0"}},
      {"nu 0.5",
       [](json& j) { j["material"]["poisson_ratio"] = 0.5; },
       {"material.poisson_ratio:", "(-1, 0.5)", "found 0.5"}},
      {"nu -1",
       [](json& j) { j["material"]["poisson_ratio"] = -1; },
       {"material.poisson_ratio:", "found -1"}},
      {"nu 0.7",
       [](json& j) { j["material"]["poisson_ratio"] = 0.7; },
       {"material.poisson_ratio:"}},
      {"density zero",
       [](json& j) { j["material"]["density"] = 0; },
       {"material.density:", "must be > 0"}},
      {"rotation unknown",
       [](json& j) { j["material"]["rotation"] = "polr"; },
       {"material.rotation:", "unknown element rotation \"polr\"", "did you mean \"polar\"?"}},
      {"rotation not a string",
       [](json& j) { j["material"]["rotation"] = 1; },
       {"material.rotation:"}},
      // negative stiffness, damping, noise
      {"ligament stiffness negative",
       [](json& j) { j["ligaments"][1]["stiffness"] = -300; },
       {"ligaments[1] \"middle\".stiffness:", "must be >= 0, found -300"}},
      {"control stiffness negative",
       [](json& j) { j["control"]["stiffness"] = -1; },
       {"control.stiffness:", "must be >= 0"}},
      {"event stiffness negative",
       [](json& j) { j["events"][0]["stiffness"] = -0.01; },
       {"events[0].stiffness:", "must be >= 0"}},
      {"event time negative",
       [](json& j) { j["events"][0]["time"] = -1; },
       {"events[0].time:", "must be >= 0"}},
      {"rayleigh stiffness negative",
       [](json& j) {
         j["damping"] = {{"rayleigh_stiffness", -0.1}};
       },
       {"damping.rayleigh_stiffness:", "must be >= 0"}},
      {"rayleigh mass negative",
       [](json& j) {
         j["damping"] = {{"rayleigh_mass", -0.1}};
       },
       {"damping.rayleigh_mass:", "must be >= 0"}},
      {"noise negative",
       [](json& j) { j["observations"]["noise_std"] = -0.0005; },
       {"observations.noise_std:", "must be 0 to 1 m, found -0.0005"}},
      // trajectories
      {"trajectory type unknown",
       [](json& j) { j["control"]["trajectory"]["type"] = "linaer"; },
       {"control.trajectory.type:", "did you mean \"linear\""}},
      {"waypoint times not increasing",
       [](json& j) {
         j["control"]["trajectory"] = json::parse(
             R"({"type": "waypoints", "times": [0, 1, 1],
                 "positions": [[0,0,0],[1,0,0],[2,0,0]]})");
       },
       {"control.trajectory.times[2]:", "must strictly increase"}},
      {"waypoint times decreasing",
       [](json& j) {
         j["control"]["trajectory"] = json::parse(
             R"({"type": "waypoints", "times": [2, 1], "positions": [[0,0,0],[1,0,0]]})");
       },
       {"control.trajectory.times[1]:", "time 1 does not come after the previous time 2"}},
      {"waypoint length mismatch",
       [](json& j) {
         j["control"]["trajectory"] = json::parse(
             R"({"type": "waypoints", "times": [0, 1, 2], "positions": [[0,0,0],[1,0,0]]})");
       },
       {"control.trajectory.positions:", "2 positions for 3 times"}},
      {"waypoints empty",
       [](json& j) {
         j["control"]["trajectory"] =
             json::parse(R"({"type": "waypoints", "times": [], "positions": []})");
       },
       {"control.trajectory.times:", "at least one waypoint"}},
      {"waypoint position malformed",
       [](json& j) {
         j["control"]["trajectory"] =
             json::parse(R"({"type": "waypoints", "times": [0, 1], "positions": [[0,0,0],[1,0]]})");
       },
       {"control.trajectory.positions[1]:", "3 numbers"}},
      {"trajectory file not there",
       [](json& j) {
         j["control"]["trajectory"] = {{"type", "file"}, {"file", "missing.csv"}};
       },
       {"control.trajectory.file:", "file not found", "missing.csv"}},
  };
  for (const BadCase& c : cases) {
    SCOPED_TRACE(c.label);
    json j = valid_scenario();
    c.edit(j);
    expect_error(write(j), c.expected);
  }
}

TEST_F(ScenarioLoadTest, MalformedTrajectoryCsvNamesTheCsvAndLine) {
  const std::string csv =
      dir_.write("traj.csv", "time,x,y,z\n0,0.3,0.075,0.075\n0.5,0.3,oops,0.075\n");
  json j = valid_scenario();
  j["control"]["trajectory"] = {{"type", "file"}, {"file", "traj.csv"}};
  expect_error(write(j), {"control.trajectory.file:", csv + " line 3", "column y"});
  dir_.write("traj.csv", "time,x,y,z\n0,0.3,0.075,0.075\n0,0.3,0.075,0.075\n");
  expect_error(write(j), {"control.trajectory.file:", csv + " line 3", "must strictly increase"});
  dir_.write("traj.csv", "0,0.3,0.075,0.075\n");
  expect_error(write(j), {"control.trajectory.file:", csv + " line 1", "header"});
}

TEST_F(ScenarioLoadTest, BadMeshContentIsReportedUnderMeshFile) {
  dir_.write("bad.msh", "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n1\n1 0 0 0\n$EndNodes\n");
  json j = valid_scenario();
  j["mesh"]["file"] = "bad.msh";
  expect_error(write(j), {"mesh.file:", "bad.msh"});
}

// ---------------------------------------------------------------------------------------
// The shipped scenarios and the SOFA reference.

bool contains(const std::vector<int>& nodes, int node) {
  return std::find(nodes.begin(), nodes.end(), node) != nodes.end();
}

// Checks shared by the shipped scenarios: observed nodes are on the surface (a camera sees
// only that), and no node serves two roles (an observed node tied to the SO or to a
// ligament would say little about the ligaments).
void expect_roles_apart(const Scenario& s) {
  const std::vector<int> surface = boundary_nodes(s.mesh);
  std::set<int> used(s.control.nodes.begin(), s.control.nodes.end());
  for (const Ligament& ligament : s.ligaments) {
    for (int node : ligament.nodes) {
      EXPECT_TRUE(used.insert(node).second)
          << "node " << node << " of " << ligament.name << " is also in another set";
    }
  }
  for (int node : s.observations.nodes) {
    EXPECT_TRUE(std::binary_search(surface.begin(), surface.end(), node))
        << "observed node " << node << " is not on the surface";
    EXPECT_EQ(used.count(node), 0u) << "observed node " << node << " is a ligament or SO node";
  }
}

// The settings both shipped scenarios take from the seed paper (sections 3.1, 3.2).
void expect_paper_settings(const Scenario& s) {
  EXPECT_EQ(s.material.young_modulus, 5000.0);
  EXPECT_EQ(s.material.poisson_ratio, 0.45);
  EXPECT_EQ(s.material.density, 1000.0);
  EXPECT_EQ(s.damping.rayleigh_stiffness, 0.1);
  EXPECT_EQ(s.damping.rayleigh_mass, 0.1);
  EXPECT_EQ(s.time.dt, 0.01);
  EXPECT_EQ(s.control.stiffness, 1e4);
  EXPECT_EQ(s.solver.cg_tolerance, 1e-10);
  ASSERT_EQ(s.ligaments.size(), 3u);
  EXPECT_EQ(s.ligament_stiffness_at(0.0), (std::vector<double>{150.0, 300.0, 200.0}));
  ASSERT_EQ(s.events.size(), 1u);
  EXPECT_EQ(s.events[0].ligament_name, "middle");
  EXPECT_EQ(s.events[0].stiffness, 0.01);
  EXPECT_EQ(s.observations.nodes.size(), 12u);
  EXPECT_EQ(s.observations.noise_std, 0.0005);
  ASSERT_TRUE(s.filter.has_value());
  EXPECT_EQ(s.filter->estimate, (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(s.filter->observation_std, 0.0005);
  EXPECT_EQ(s.filter->sigma_points, "simplex");
}

TEST(ShippedScenarioTest, BoxLoads) {
  const Scenario s = load_scenario(kSourceDir + "/scenarios/box.json");
  expect_paper_settings(s);
  EXPECT_EQ(s.name, "box");
  EXPECT_EQ(s.mesh.node_count(), 403);
  EXPECT_EQ(s.mesh.tetrahedron_count(), 1344);
  EXPECT_EQ(s.time.steps, 1500);
  EXPECT_EQ(s.ligaments[0].name, "corner_a");
  EXPECT_EQ(s.ligaments[1].name, "middle");
  EXPECT_EQ(s.ligaments[2].name, "corner_b");
  EXPECT_EQ(s.ligaments[0].nodes.size(), 7u);
  EXPECT_EQ(s.ligaments[1].nodes.size(), 5u);
  EXPECT_EQ(s.ligaments[2].nodes.size(), 7u);
  EXPECT_TRUE(contains(s.ligaments[0].nodes, 1)) << "corner (0, 0, 0)";
  EXPECT_TRUE(contains(s.ligaments[2].nodes, 2)) << "corner (0, 0.15, 0.15)";
  for (int node : s.ligaments[1].nodes) EXPECT_EQ(s.mesh.nodes[static_cast<size_t>(node)].x(), 0.0);
  EXPECT_EQ(s.control.nodes.size(), 8u);
  for (int node : s.control.nodes) EXPECT_EQ(s.mesh.nodes[static_cast<size_t>(node)].x(), 0.3);
  EXPECT_EQ(s.control.trajectory.type, Trajectory::Type::linear);
  EXPECT_EQ(s.events[0].time, 7.5);
  for (int node : s.observations.nodes) {
    EXPECT_EQ(s.mesh.nodes[static_cast<size_t>(node)].z(), 0.15) << "observed on the top face";
  }
  // Over the run the SO moves a few centimetres.
  const double travel =
      (s.control.trajectory.position(s.time.steps * s.time.dt, s.control.start) - s.control.start)
          .norm();
  EXPECT_GT(travel, 0.03);
  EXPECT_LT(travel, 0.1);
  expect_roles_apart(s);
}

TEST(ShippedScenarioTest, LiverLoads) {
  const Scenario s = load_scenario(kSourceDir + "/scenarios/liver.json");
  expect_paper_settings(s);
  EXPECT_EQ(s.name, "liver");
  EXPECT_EQ(s.mesh.node_count(), 181);
  EXPECT_EQ(s.mesh.tetrahedron_count(), 596);
  EXPECT_NEAR(s.mesh_report.total_volume, 1.31e-3, 0.01e-3) << "about 1.3 L once scaled to metres";
  EXPECT_EQ(s.time.steps, 2000);
  EXPECT_EQ(s.events[0].time, 10.0);
  for (const Ligament& ligament : s.ligaments) {
    EXPECT_GE(ligament.nodes.size(), 3u) << ligament.name;
    EXPECT_LE(ligament.nodes.size(), 5u) << ligament.name;
  }
  EXPECT_EQ(s.control.nodes.size(), 3u);
  const Trajectory& t = s.control.trajectory;
  ASSERT_EQ(t.type, Trajectory::Type::file);
  EXPECT_EQ(t.file, "liver_trajectory.csv");
  ASSERT_EQ(t.times.size(), 2001u) << "0.01 s samples over the 20 s run";
  EXPECT_EQ(t.times.back(), 20.0);
  // The record starts at so(0): 6 printed decimals leave at most 5e-7 m per coordinate.
  EXPECT_LT((t.position(0.0, s.control.start) - s.control.start).lpNorm<Eigen::Infinity>(), 5.1e-7);
  EXPECT_LT((t.positions[1] - t.positions[0]).norm(), 1e-5) << "starts at rest";
  double reach = 0.0;
  for (const Eigen::Vector3d& p : t.positions)
    reach = std::max(reach, (p - s.control.start).norm());
  EXPECT_GT(reach, 0.015);
  EXPECT_LT(reach, 0.04);
  expect_roles_apart(s);
}

TEST(ShippedScenarioTest, SofaReferenceScenarioLoads) {
  const std::string reference = kSharedDir + "/data/sofa-reference";
  if (!fs::exists(reference + "/scenario.json")) SIGMAFEM_MISSING("no " << reference);
  TempDir dir;
  dir.copy(reference + "/scenario.json", "scenario.json");
  dir.copy(reference + "/traj.csv", "traj.csv");
  dir.copy(kSharedDir + "/data/liver/liver.msh", "liver.msh");
  const Scenario s = load_scenario(dir.file("scenario.json"));
  EXPECT_EQ(s.name, "sofa-cmp");
  EXPECT_EQ(s.mesh.node_count(), 181);
  EXPECT_EQ(s.mesh.tetrahedron_count(), 596);
  EXPECT_EQ(s.mesh_spec.scale, 1.0);
  EXPECT_EQ(s.material.density, 1.0);
  EXPECT_EQ(s.time.steps, 1000);
  ASSERT_EQ(s.ligaments.size(), 3u);
  EXPECT_EQ(s.ligaments[0].nodes, (std::vector<int>{0, 2, 3, 45}));
  EXPECT_EQ(s.ligaments[1].nodes, (std::vector<int>{37, 38, 39, 113}));
  EXPECT_EQ(s.ligaments[2].nodes, (std::vector<int>{56, 57, 64, 65}));
  EXPECT_EQ(s.ligament_stiffness_at(5.0), (std::vector<double>{4000.0, 4000.0, 4000.0}));
  EXPECT_EQ(s.control.nodes, (std::vector<int>{78}));
  EXPECT_EQ(s.control.start, Eigen::Vector3d(1.29372, 4.57712, -0.699486));
  const Trajectory& t = s.control.trajectory;
  ASSERT_EQ(t.type, Trajectory::Type::file);
  EXPECT_EQ(t.times, (std::vector<double>{0, 0.02, 5.02, 20}));
  EXPECT_EQ(t.position(0.0, s.control.start), s.control.start);
  EXPECT_NEAR(
      (t.position(2.52, s.control.start) - Eigen::Vector3d(1.29372, 5.07712, -0.699486)).norm(),
      0.0, 1e-12);
  EXPECT_EQ(s.observations.nodes, (std::vector<int>{78, 0, 113, 57, 111, 124, 87, 73, 51, 76}));
  EXPECT_EQ(s.observations.noise_std, 0.0);
  EXPECT_TRUE(s.events.empty());
  EXPECT_FALSE(s.filter.has_value());
  EXPECT_EQ(s.gravity, Eigen::Vector3d::Zero());
}

}  // namespace
}  // namespace sigmafem
