// Candidate regions for an unmodelled ligament (diagnose's extra_ligament:REGION) when a
// scenario does not list its own: the boundary surface split into patches of nearby nodes.
#pragma once

#include <vector>

#include "host/mesh/mesh.h"
#include "host/scenario/scenario.h"

namespace sigmafem {

// How many regions a scenario without `candidate_regions` gets.
constexpr int kAutomaticRegionCount = 6;

// The boundary nodes outside `excluded` (the ligaments' and the control's: a spring is already
// there) split into `count` regions by k-means on their rest positions, seeded with farthest
// points (the node farthest from the centroid first): deterministic, so a region's name means
// the same nodes on every run. Named surface_1 .. surface_N in seeding order; fewer when there
// are fewer nodes. `stiffness` is unused (0).
std::vector<Ligament> automatic_surface_regions(const Mesh& mesh, int count, const std::vector<int>& excluded);

}  // namespace sigmafem
