#include "host/generator/truth_mesh.h"

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "host/common/input_error.h"
#include "host/scenario/scenario_on_mesh.h"

namespace sigmafem {

namespace {

// The same limit as the scenario's mesh.refine: each level is x8 tetrahedra.
constexpr int kMaxTruthRefine = 3;

std::string levels(int n) { return std::to_string(n) + (n == 1 ? " more level" : " more levels"); }

// Reads, transforms, orients and checks FILE like load_scenario does the scenario's mesh.
Mesh read_truth_mesh(const Scenario& scenario, const std::string& file) {
  const std::string option = "--truth-mesh " + file;
  std::error_code error;
  if (!std::filesystem::is_regular_file(file, error)) throw InputError(option + ": file not found");
  try {
    Mesh mesh = read_mesh(file);
    transform_mesh(mesh, scenario.mesh_spec.scale, scenario.mesh_spec.translate);
    orient_and_check(mesh, file);
    return mesh;
  } catch (const InputError& e) {
    throw InputError(option + ": " + e.what());
  }
}

// Puts `spread` (nodes and parts) into `set`; nothing when it is empty.
void apply_spread(const std::vector<SpringShare>& spread, SpringSet& set) {
  if (spread.empty()) return;
  set.nodes.clear();
  set.shares.clear();
  for (const SpringShare& s : spread) {
    set.nodes.push_back(s.node);
    set.shares.push_back(s.share);
  }
}

}  // namespace

Model TruthMesh::model() const {
  Model model = make_model(scenario);
  for (std::size_t l = 0; l < ligament_spread.size(); ++l) apply_spread(ligament_spread[l], model.ligaments[l]);
  for (std::size_t r = 0; r < region_spread.size(); ++r) apply_spread(region_spread[r], model.candidate_regions[r]);
  apply_spread(control_spread, model.control);
  return model;
}

std::vector<int> TruthMesh::nearest_observed_nodes() const {
  std::vector<int> nodes;
  for (const ObservedPoint& point : observed) nodes.push_back(point.nearest_node());
  return nodes;
}

TruthMesh make_truth_mesh(const Scenario& scenario, const TruthMeshOptions& options) {
  if (options.refine && options.file)
    throw InputError("--truth-refine and --truth-mesh: give one or the other (the truth runs on "
                     "the scenario's mesh refined, or on another mesh file)");
  if (options.refine && (*options.refine < 1 || *options.refine > kMaxTruthRefine))
    throw InputError("--truth-refine " + std::to_string(*options.refine) + ": must be 1 to " +
                     std::to_string(kMaxTruthRefine) +
                     " (levels of uniform refinement of the scenario's mesh, each x8 tetrahedra)");
  TruthMesh truth;
  const ObservedPoints& observed = scenario.observations.observed;
  if (options.file) {
    truth.scenario = scenario_on_mesh(scenario, read_truth_mesh(scenario, *options.file),
                                      "--truth-mesh " + *options.file);
    truth.description = *options.file;
  } else {
    truth.scenario = scenario;
    if (options.refine) {
      // Node sets keep their indices (refine_uniform keeps the old nodes' indices); the new
      // elements are checked as load_scenario checks mesh.refine's.
      for (int level = 0; level < *options.refine; ++level)
        truth.scenario.mesh = refine_uniform(truth.scenario.mesh);
      orient_and_check(truth.scenario.mesh, "--truth-refine " + std::to_string(*options.refine));
      truth.description = "the scenario's mesh refined " + levels(*options.refine);
      // Regions are element sets: selected again on the refined elements (by centroid, or by
      // the label the children keep).
      for (Region& region : truth.scenario.regions)
        region.elements = region_elements(truth.scenario.mesh, region);
      if (options.spread_springs) {
        const Mesh& fine = truth.scenario.mesh;
        for (const Ligament& ligament : scenario.ligaments)
          truth.ligament_spread.push_back(spread_spring(scenario.mesh, ligament.nodes, fine));
        for (const Ligament& region : scenario.candidate_regions)
          truth.region_spread.push_back(spread_spring(scenario.mesh, region.nodes, fine));
        if (!scenario.control.nodes.empty()) truth.control_spread = spread_spring(scenario.mesh, scenario.control.nodes, fine);
        truth.description += ", the springs spread over it";
      }
    } else {
      truth.description = "the scenario's mesh";
    }
  }
  if (!options.refine && !options.file) {
    truth.observed = observed;   // the model's own: the data are bit for bit as before
    return truth;
  }
  const double limit = kMaxOutsideShare * bounding_diagonal(truth.scenario.mesh);
  for (std::size_t p = 0; p < observed.size(); ++p) {
    const Eigen::Vector3d rest = observed[p].at_rest(scenario.mesh);
    const MeshLocation location = locate_point(truth.scenario.mesh, rest);
    if (location.outside_distance > limit) {
      std::ostringstream what;
      what << (options.file ? "--truth-mesh " + *options.file : "--truth-refine")
           << ": observed point " << p << " (" << observed_point_name(scenario.observations, p)
           << ") lies " << location.outside_distance * 1e3
           << " mm outside the truth mesh, more than " << kMaxOutsideShare * 100
           << "% of its size: do the meshes describe the same organ in the same frame (mesh.scale, "
              "mesh.translate)?";
      throw InputError(what.str());
    }
    truth.max_outside_distance = std::max(truth.max_outside_distance, location.outside_distance);
    truth.observed.push_back(ObservedPoint::at(truth.scenario.mesh, location));
  }
  return truth;
}

}  // namespace sigmafem
