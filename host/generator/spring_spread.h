// How `generate --truth-refine` carries the scenario's springs (ligaments and the SO's grip)
// onto the refined mesh. On the scenario's mesh a spring set lumps an attachment into a few
// nodes: each node stands for the tissue its shape function covers. Kept on the same nodes of
// a refined mesh, the same total acts on a smaller and smaller patch at each level, and a
// point load on a 3D body does not converge (its displacement grows without bound as the mesh
// is refined): the truth then drifts away from the model with every level instead of towards
// the organ the model discretises (measured, README "Commands": the observed points 0.51 mm
// off the model's with one level, 1.04 mm with two on box.json; 1.21 and 2.18 mm on the liver).
//
// Spread, each coarse node's share of the spring goes to the refined nodes inside the support
// of its coarse shape function phi_i, in proportion to phi_i at the refined node times the
// refined node's lumped measure: its lumped boundary area where the coarse node lies on the
// organ's surface (a ligament or a grip holds the surface), else its lumped volume. That is
// the refined mesh's lumping of the attachment the coarse node lumps, so the same attachment
// is simulated at every level and the truth converges as the level rises.
#pragma once

#include <vector>

#include "host/mesh/mesh.h"

namespace sigmafem {

// One refined node's share of a spring set's total stiffness.
struct SpringShare {
  int node = 0;
  double share = 0.0;
};

// The shares (summing to 1, sorted by node) of a spring set whose total is split equally among
// `coarse_nodes` of `coarse`, carried onto `fine`, a uniform refinement of `coarse` (its first
// nodes are `coarse`'s, at the same positions).
std::vector<SpringShare> spread_spring(const Mesh& coarse, const std::vector<int>& coarse_nodes, const Mesh& fine);

}  // namespace sigmafem
