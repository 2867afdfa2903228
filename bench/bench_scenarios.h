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

}  // namespace sigmafem::bench
