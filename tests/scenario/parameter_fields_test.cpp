// Parameter fields (docs/FORMATS.md, issue 19). regions: parts of the organ with a Young's
// modulus of their own, selected by element centroids; the model scales their elements' Lame
// terms; the filter may estimate their moduli after the ligaments (filter.estimate_young_modulus).
// filter.estimate_springs: a ligament estimated spring by spring, split in the estimation's
// model. Bad values are named.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <set>

#include "host/common/input_error.h"
#include "host/engine/estimation_options.h"
#include "host/mesh/mesh.h"
#include "host/model/estimated_parameters.h"
#include "host/model/model.h"
#include "host/scenario/scenario.h"
#include "host/scenario/scenario_on_mesh.h"
#include "temp_path.h"
#include "tests/mesh/mesh_test_support.h"

namespace sigmafem {
namespace {

using nlohmann::json;

class ParameterFieldsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_.copy(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.msh", "box.msh");
    scenario_ = json::parse(R"({
      "format": "sigmafem-scenario/1",
      "mesh": {"file": "box.msh"},
      "material": {"young_modulus": 5000, "poisson_ratio": 0.45, "density": 1000},
      "time": {"dt": 0.01, "steps": 10},
      "ligaments": [{"name": "corner_a", "select": {"near": [0, 0, 0], "radius": 0.035}, "stiffness": 150}],
      "regions": [
        {"name": "left", "select": {"box": {"min": [-1, -1, -1], "max": [0.1, 1, 1]}}, "young_modulus": 25000},
        {"name": "middle", "select": {"box": {"min": [0.1, -1, -1], "max": [0.2, 1, 1]}}}
      ],
      "control": {"select": {"near": [0.3, 0.075, 0.075], "radius": 0.032}, "stiffness": 10000,
                  "trajectory": {"type": "linear", "velocity": [0.004, 0.002, 0.001]}},
      "observations": {"nodes": [1, 2]},
      "filter": {"estimate": ["corner_a"], "initial_stiffness": [300],
                 "estimate_young_modulus": ["middle", "left"], "initial_young_modulus": [4000, 6000],
                 "observation_std": 0.001}
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

Eigen::Vector3d centroid(const Mesh& mesh, int e) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int node : mesh.tetrahedra[static_cast<std::size_t>(e)]) c += 0.25 * mesh.nodes[static_cast<std::size_t>(node)];
  return c;
}

TEST_F(ParameterFieldsTest, ARegionHoldsTheElementsWhoseCentroidItsSelectionHolds) {
  const Scenario s = load(scenario_);
  ASSERT_EQ(s.regions.size(), 2u);
  EXPECT_EQ(s.regions[0].young_modulus, 25000.0);
  EXPECT_EQ(s.regions[1].young_modulus, 5000.0) << "left out: the material's";
  const std::set<int> left(s.regions[0].elements.begin(), s.regions[0].elements.end());
  const std::set<int> middle(s.regions[1].elements.begin(), s.regions[1].elements.end());
  ASSERT_FALSE(left.empty());
  ASSERT_FALSE(middle.empty());
  for (int e = 0; e < s.mesh.tetrahedron_count(); ++e) {
    const double x = centroid(s.mesh, e).x();
    EXPECT_EQ(left.count(e) == 1, x <= 0.1 + kSelectionSlack) << e;
    EXPECT_EQ(middle.count(e) == 1, x >= 0.1 - kSelectionSlack && x <= 0.2 + kSelectionSlack) << e;
  }
}

TEST_F(ParameterFieldsTest, TheModelScalesItsRegionsLameTermsByTheirModulus) {
  const Scenario s = load(scenario_);
  json plain = scenario_;
  plain.erase("regions");
  plain["filter"].erase("estimate_young_modulus");
  plain["filter"].erase("initial_young_modulus");
  const Model with = make_model(s), without = make_model(load(plain));
  const std::set<int> left(s.regions[0].elements.begin(), s.regions[0].elements.end());
  for (int e = 0; e < with.element_count(); ++e) {
    const double scale = left.count(e) ? 5.0 : 1.0;
    EXPECT_DOUBLE_EQ(with.elements[e].vlambda, scale * without.elements[e].vlambda) << e;
    EXPECT_DOUBLE_EQ(with.elements[e].vmu, scale * without.elements[e].vmu) << e;
  }
  ASSERT_EQ(with.regions.size(), 2u);
  EXPECT_EQ(with.regions[0].name, "left");
  EXPECT_EQ(with.regions[0].young_modulus, 25000.0);
}

TEST_F(ParameterFieldsTest, TheFilterEstimatesTheModuliAfterTheLigaments) {
  const Scenario s = load(scenario_);
  EXPECT_EQ(s.filter->estimate_regions, (std::vector<int>{1, 0}));
  EXPECT_EQ(s.parameter_names(), (std::vector<std::string>{"corner_a", "E:middle", "E:left"}));
  EXPECT_EQ(s.truth_names(), (std::vector<std::string>{"corner_a", "E:left", "E:middle"}));
  const EstimationOptions options = estimation_options(s);
  ASSERT_EQ(options.roukf.initial_theta.size(), 3);
  EXPECT_DOUBLE_EQ(options.roukf.initial_theta[1], std::log(4000.0));
  EXPECT_DOUBLE_EQ(options.roukf.initial_theta[2], std::log(6000.0));
  EXPECT_EQ(options.stiffness_count, 1) << "a modulus is no stiffness to check against N/m bounds";
}

TEST_F(ParameterFieldsTest, OnAFinerMeshTheRegionsAreSelectedAgain) {
  const Scenario s = load(scenario_);
  const Scenario fine = scenario_on_mesh(s, refine_uniform(s.mesh), "refined");
  ASSERT_EQ(fine.regions.size(), 2u);
  for (int e : fine.regions[0].elements) EXPECT_LE(centroid(fine.mesh, e).x(), 0.1 + kSelectionSlack);
  // About the same volume: 8 children per element, the border moved by less than an element.
  const double ratio = static_cast<double>(fine.regions[0].elements.size()) / (8.0 * static_cast<double>(s.regions[0].elements.size()));
  EXPECT_NEAR(ratio, 1.0, 0.25);
}

TEST_F(ParameterFieldsTest, BadRegionsAreNamed) {
  json overlap = scenario_;
  overlap["regions"][1]["select"]["box"]["min"][0] = 0.05;
  EXPECT_NE(error_of(overlap).find("also in regions[0] \"left\""), std::string::npos) << error_of(overlap);
  json empty = scenario_;
  empty["regions"][1]["select"] = json::parse(R"({"near": [5, 5, 5], "radius": 0.01})");
  EXPECT_NE(error_of(empty).find("regions[1] \"middle\".select: holds the centroid of no tetrahedron"), std::string::npos)
      << error_of(empty);
  json soft = scenario_;
  soft["regions"][0]["young_modulus"] = 0;
  EXPECT_NE(error_of(soft).find("young_modulus"), std::string::npos) << error_of(soft);
  json twice = scenario_;
  twice["regions"][1]["name"] = "left";
  EXPECT_NE(error_of(twice).find("duplicate region name"), std::string::npos) << error_of(twice);
  json unknown = scenario_;
  unknown["filter"]["estimate_young_modulus"][0] = "tumour";
  EXPECT_NE(error_of(unknown).find("no region \"tumour\" (regions: left, middle)"), std::string::npos)
      << error_of(unknown);
  json counts = scenario_;
  counts["filter"]["initial_young_modulus"] = json::array({4000});
  EXPECT_NE(error_of(counts).find("1 values for 2 regions"), std::string::npos) << error_of(counts);
  json no_prior = scenario_;
  no_prior["filter"].erase("initial_young_modulus");
  EXPECT_NE(error_of(no_prior).find("needs initial_young_modulus"), std::string::npos) << error_of(no_prior);
}

// A region by label: the tetrahedra of one physical group of the mesh file (box.msh with the
// even element ids' physical tag made 2).
TEST_F(ParameterFieldsTest, ARegionByLabelHoldsThatPhysicalGroup) {
  std::ifstream in(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.msh");
  std::string line, text;
  int relabelled = 0;
  bool elements = false;
  while (std::getline(in, line)) {
    if (line == "$Elements") elements = true;
    std::istringstream in_line(line);
    std::vector<std::string> fields;
    for (std::string field; in_line >> field;) fields.push_back(field);
    // "id 4 n-tags physical ...": a tetrahedron with tags.
    if (elements && fields.size() > 4 && fields[1] == "4" && fields[2] != "0" && std::stoll(fields[0]) % 2 == 0) {
      fields[3] = "2";
      line.clear();
      for (const std::string& field : fields) line += (line.empty() ? "" : " ") + field;
      ++relabelled;
    }
    text += line + "\n";
  }
  dir_.write("box.msh", text);
  json labelled = scenario_;
  labelled["regions"] = json::parse(R"([{"name": "even", "label": 2, "young_modulus": 10000}])");
  labelled["filter"]["estimate_young_modulus"] = json::array({"even"});
  labelled["filter"]["initial_young_modulus"] = json::array({5000});
  const Scenario s = load(labelled);
  ASSERT_EQ(s.regions.size(), 1u);
  EXPECT_EQ(static_cast<int>(s.regions[0].elements.size()), relabelled);
  for (int e : s.regions[0].elements) EXPECT_EQ(s.mesh.labels[static_cast<std::size_t>(e)], 2);
  json missing = labelled;
  missing["regions"][0]["label"] = 3;
  EXPECT_NE(error_of(missing).find("no tetrahedron of mesh box.msh has label 3 (its labels: 1, 2)"), std::string::npos)
      << error_of(missing);
  json both = labelled;
  both["regions"][0]["select"] = json::parse(R"({"near": [0, 0, 0], "radius": 0.1})");
  EXPECT_NE(error_of(both).find("either \"select\""), std::string::npos) << error_of(both);

  // The same labels as a VTK file's CELL_DATA array hold the same tetrahedra; a VTK file
  // without one is refused, saying so.
  const Mesh file_mesh = read_mesh(dir_.path() + "/box.msh");
  json from_vtk = labelled;
  from_vtk["mesh"]["file"] = "box.vtk";
  dir_.write("box.vtk", test::vtk_ascii_text(file_mesh));
  EXPECT_EQ(load(from_vtk).regions[0].elements, s.regions[0].elements);
  dir_.write("box.vtk", test::vtk51_text(file_mesh, false));
  EXPECT_NE(error_of(from_vtk).find("mesh box.vtk labels no element (no one-component integer array in CELL_DATA"),
            std::string::npos)
      << error_of(from_vtk);
}

TEST_F(ParameterFieldsTest, ALigamentEstimatedPerSpringIsSplitInTheModel) {
  json with_springs = scenario_;
  with_springs["ligaments"].push_back(json::parse(R"({"name": "far", "nodes": [3, 5], "stiffness": 80})"));
  with_springs["filter"]["estimate_springs"] = json::array({"far"});
  with_springs["filter"]["initial_spring_stiffness"] = json::array({30});
  const Scenario s = load(with_springs);
  EXPECT_EQ(s.parameter_names(), (std::vector<std::string>{"corner_a", "far@3", "far@5", "E:middle", "E:left"}));
  EXPECT_EQ(s.truth_names(), (std::vector<std::string>{"corner_a", "far", "far@3", "far@5", "E:left", "E:middle"}));
  const EstimationOptions options = estimation_options(s);
  ASSERT_EQ(options.roukf.initial_theta.size(), 5);
  EXPECT_DOUBLE_EQ(options.roukf.initial_theta[2], std::log(30.0));
  EXPECT_EQ(options.stiffness_count, 3);
  Model model = make_model(s);
  const EstimatedParameters estimated = estimated_parameters(*s.filter, model);
  EXPECT_EQ(estimated.ligaments, (std::vector<int>{0, 2, 3}));
  ASSERT_EQ(model.ligaments.size(), 4u);
  EXPECT_EQ(model.ligaments[1].stiffness, 0.0);
  EXPECT_EQ(model.ligaments[2].name, "far@3");
  EXPECT_EQ(model.ligaments[2].nodes, (std::vector<int>{3}));
  EXPECT_EQ(model.ligaments[3].stiffness, 40.0) << "its part of the ligament";
  json both = with_springs;
  both["filter"]["estimate"] = json::array({"corner_a", "far"});
  both["filter"]["initial_stiffness"] = json::array({300, 80});
  EXPECT_NE(error_of(both).find("also in filter.estimate"), std::string::npos) << error_of(both);
  json no_prior = with_springs;
  no_prior["filter"].erase("initial_spring_stiffness");
  EXPECT_NE(error_of(no_prior).find("needs initial_spring_stiffness"), std::string::npos) << error_of(no_prior);
}

}  // namespace
}  // namespace sigmafem
