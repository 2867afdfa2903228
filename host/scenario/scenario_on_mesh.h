// The scenario on another mesh of the same organ: `generate --truth-mesh FILE` simulates the
// truth on a different discretisation, so that the data carries the model-form error that
// measured data always has. Every node set is resolved again on the other mesh, each by the
// way it was written (Ligament::selection):
//   select near / box   the selection is made again on the other mesh;
//   nodes               each listed node is mapped to the node of the other mesh at the same
//                       rest position (within kCoincidentTolerance);
//   automatic regions   (candidate_regions left out or {"automatic": N}) each boundary node of
//                       the other mesh that no spring holds joins the region of the nearest
//                       node of the scenario's regions, so that surface_3 is the same patch of
//                       the organ on both meshes (k-means there could number the patches
//                       differently).
// Stiffnesses are totals, so a set with more nodes on the finer mesh gets less per node.
#pragma once

#include <string>

#include "host/mesh/mesh.h"
#include "host/scenario/scenario.h"

namespace sigmafem {

// Two nodes of different meshes are the same material point when closer than this (m): far
// below any element size, far above the rounding of a mesh file's coordinates.
constexpr double kCoincidentTolerance = 1e-6;

// `scenario` with `mesh` (in metres, oriented and checked) in place of its mesh and its
// ligaments, control and candidate regions resolved on it. The control keeps the scenario's
// so(0): the same SO motion drives both meshes (its springs pull with so(t) - so(0)), although
// the centroid of the control nodes moves a little with the discretisation. Observed nodes are
// not mapped (an observed point needs no node of the other mesh: the generator interpolates
// there) and are left empty. Throws InputError "SOURCE: FIELD: problem" (`source` names the
// other mesh, e.g. "--truth-mesh box_fine.msh") for a listed node with no coincident node and
// for a selection or region that catches no node of the other mesh.
Scenario scenario_on_mesh(const Scenario& scenario, Mesh mesh, const std::string& source);

}  // namespace sigmafem
