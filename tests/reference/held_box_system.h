// The implicit-Euler system a held-box simulation (structured_mesh.h, held_box) solves at its
// next step, assembled apart from the simulation: what the preconditioner tests
// (factorised_preconditioner_test.cpp, spring_correction_test.cpp) solve with CG. Header-only
// (the test build compiles only *_test.cpp files).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "host/reference/corotational.h"
#include "host/reference/implicit_euler.h"
#include "host/reference/reference_simulation.h"
#include "tests/reference/structured_mesh.h"

namespace sigmafem::test {

struct HeldBoxSystem {
  std::vector<Frame> frames;
  Eigen::VectorXd springs, b;
  std::unique_ptr<ImplicitEulerSystem> A;
};

// `simulation`'s system for step `step` (the SO at step * dt): its frames, springs, matrix
// and right-hand side.
inline HeldBoxSystem held_box_system(const HeldBox& held, const ReferenceSimulation& simulation, int step) {
  HeldBoxSystem s;
  element_frames(held.model, simulation.positions(), s.frames);
  s.springs = simulation.node_springs();
  s.A = std::make_unique<ImplicitEulerSystem>(held.model, s.frames, s.springs);
  s.b = s.A->right_hand_side(
      simulation.forces(simulation.positions(), s.frames, held_box_so(held.model, step * held.model.dt)),
      simulation.velocities());
  return s;
}

}  // namespace sigmafem::test
