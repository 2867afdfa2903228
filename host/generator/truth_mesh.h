// TruthMesh: the mesh `generate` simulates the truth on, and where the model's observed points
// lie on it. By default the scenario's own mesh; with GenerateOptions::truth_mesh another
// discretisation of the same organ, so that the data carries the model-form error measured data
// always has (issue 13):
//   --truth-refine N   the scenario's mesh refined N more levels (refine_uniform: its nodes keep
//                      their indices, so every node set, ligaments, control, candidate regions,
//                      observed nodes, keeps its indices). Each spring is spread over the
//                      refined nodes of the attachment its coarse nodes stand for
//                      (host/generator/spring_spread.h: the same attachment at every level, so
//                      the truth converges), or with --truth-springs nodes kept on the same
//                      nodes (a point load, which grows softer with every level). Selections
//                      are NOT made again on the refined mesh: a "near" selection would catch
//                      more nodes there, with another centroid (on the liver the SO's would
//                      move 7.3 mm, see scenarios/liver_fine.json).
//   --truth-mesh FILE  another mesh file, transformed, oriented and checked like the scenario's
//                      mesh (mesh.scale, mesh.translate; not mesh.refine), with the node sets
//                      resolved again on it (host/scenario/scenario_on_mesh.h).
// Either way an observed position is the truth interpolated at the rest position of the model's
// observed point (host/mesh/mesh_locate.h), so observations.csv keeps the scenario's columns.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "host/generator/generate.h"
#include "host/generator/spring_spread.h"
#include "host/mesh/mesh_locate.h"
#include "host/mesh/observed_points.h"
#include "host/model/model.h"
#include "host/scenario/scenario.h"

namespace sigmafem {

struct TruthMesh {
  Scenario scenario;                    // the scenario on the truth mesh
  // The observed points on the truth mesh: on the scenario's mesh its own observed points; on
  // another mesh the rest position of each located on it.
  ObservedPoints observed;
  double max_outside_distance = 0.0;    // m, the farthest observed point outside the truth mesh
  std::string description;              // "the scenario's mesh", "the scenario's mesh refined 1 more level", "FILE"
  // With --truth-refine and spread springs: each ligament's, the control's and each candidate
  // region's nodes and parts on the refined mesh (empty: the scenario's node sets as they are).
  std::vector<std::vector<SpringShare>> ligament_spread, region_spread;
  std::vector<SpringShare> control_spread;

  // The truth's model: make_model(scenario) with the springs spread as above.
  Model model() const;

  // The truth node nearest each observed point (its largest weight), to mark it in the VTK.
  std::vector<int> nearest_observed_nodes() const;
};

// The truth mesh for `options` (refine 0 and no file: the scenario's mesh). Throws InputError
// naming the option for both options at once, a refinement outside 1..3, a mesh file that
// cannot be read or is invalid, node sets that cannot be resolved on it, or an observed point
// far outside it.
TruthMesh make_truth_mesh(const Scenario& scenario, const TruthMeshOptions& options);

}  // namespace sigmafem
