// The benchmarks' meshes: a shipped scenario, loaded once and refined `refinements` times
// (ligament, control and observed node indices stay valid: refinement keeps the old nodes
// first). Header-only: every *_bench.cpp is its own translation unit of one program.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "host/mesh/mesh.h"
#include "host/scenario/scenario.h"

namespace sigmafem::bench {

inline const Scenario& scenario(const std::string& name, int refinements) {
  static std::map<std::string, std::unique_ptr<Scenario>> cache;
  const std::string key = name + "/" + std::to_string(refinements);
  auto& slot = cache[key];
  if (!slot) {
    slot = std::make_unique<Scenario>(
        load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/" + name + ".json"));
    for (int r = 0; r < refinements; ++r) slot->mesh = refine_uniform(slot->mesh);
  }
  return *slot;
}

// The SO's position at a step of the scenario's trajectory.
inline Eigen::Vector3d so_position(const Scenario& s, int step) {
  return s.control.trajectory.position(step * s.time.dt, s.control.start);
}

// Adds `count` regions to `s` (also the conformance tests' many-parameter ensembles): region r
// holds the elements e with e % count = r, at the scenario's modulus, and is named "r<r>".
inline void add_interleaved_regions(Scenario& s, int count) {
  for (int r = 0; r < count; ++r) {
    Region region;
    region.name = "r" + std::to_string(r);
    for (int e = r; e < s.mesh.tetrahedron_count(); e += count) region.elements.push_back(e);
    region.young_modulus = s.material.young_modulus;
    s.regions.push_back(region);
  }
}

// `s` with p - 3 region moduli estimated beside its 3 ligaments (issue 19's parameter count):
// p - 3 interleaved regions, the prior twice the scenario's modulus.
inline Scenario with_region_moduli(Scenario s, int p) {
  const int regions = p - 3;
  add_interleaved_regions(s, regions);
  for (int r = 0; r < regions; ++r) {
    s.filter->estimate_regions.push_back(r);
    s.filter->initial_young_modulus.push_back(2.0 * s.material.young_modulus);
  }
  return s;
}

}  // namespace sigmafem::bench
