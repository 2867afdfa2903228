// Model: everything the simulation needs that does not change during a run, built once from
// a scenario (or from a mesh and a material, for tests): rest shape, per-element rest
// stiffness K_e in the element's rest frame, lumped mass, damping, springs and time step.
// Only the spring stiffnesses (and the candidate effects of host/model/effects.h, which
// `diagnose` estimates) differ between the sigma points of an ensemble; everything here is
// shared by them (ARCHITECTURE.md, "The ensemble on a device").
#pragma once

#include <Eigen/Core>
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "host/mesh/mesh.h"
#include "host/scenario/scenario.h"

namespace sigmafem {

// The rest state of one tetrahedron: the 15 numbers its stiffness needs (element.h).
struct ElementRest {
  std::array<int, 4> nodes{};           // mesh node indices, positively oriented
  std::array<double, 12> grad{};        // shape-function gradients in the rest frame, 1/m
  double volume = 0.0;                  // m^3
  double vlambda = 0.0;                 // volume * Lame lambda, N m
  double vmu = 0.0;                     // volume * Lame mu (shear modulus), N m
};

// A set of nodes held by one spring law: each node gets an equal part of the total stiffness
// unless `shares` says otherwise (generate --truth-refine spreads a spring over a refined
// mesh: host/generator/spring_spread.h).
struct SpringSet {
  std::string name;
  std::vector<int> nodes;
  double stiffness = 0.0;               // N/m, total over the nodes
  std::vector<double> shares;           // per node, in `nodes` order, summing to 1; empty: equal
  // Node k's part of a total `total` (the set's stiffness, or a sigma point's estimate of it).
  double node_part(std::size_t k, double total) const {
    return shares.empty() ? total / static_cast<double>(nodes.size()) : total * shares[k];
  }
};

// A part of the organ with a Young's modulus of its own (Scenario::regions): its elements'
// Lame terms are the material's scaled by young_modulus / material.young_modulus.
struct ElasticRegion {
  std::string name;
  std::vector<int> elements;
  double young_modulus = 0.0;           // Pa
};

struct Model {
  std::vector<Eigen::Vector3d> rest_positions;
  std::vector<ElementRest> elements;
  Eigen::VectorXd mass;                 // lumped: density * volume / 4 from each element, kg
  Material material;
  Damping damping;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  double dt = 0.01;
  SolverSpec solver;
  std::vector<SpringSet> ligaments;     // each node tied to its rest position
  // The ligament law: f = -k u (1 + |u|^2 / d0^2) per node, u its displacement; infinite d0
  // (the default): linear. The ligament_law effect (host/model/effects.h) sets it.
  double ligament_d0 = std::numeric_limits<double>::infinity();
  // The organ is driven by the SO as it was so_lag seconds earlier (the time_lag effect: the
  // observations, stamped with the SO's time, show the organ late). 0: no lag.
  double so_lag = 0.0;
  // The control nodes follow control_scale (so(t) - so(0)) (the control_scale effect: the SO's
  // record off by a factor). 1: as recorded.
  double control_scale = 1.0;
  // Surface regions where an unmodelled ligament may be (diagnose's extra_ligament:NAME).
  std::vector<SpringSet> candidate_regions;
  // Parts with their own Young's modulus, already in their elements' vlambda and vmu; an
  // ensemble may estimate theirs (host/model/estimated_parameters.h).
  std::vector<ElasticRegion> regions;
  SpringSet control;                    // each node tied to so(t) + rest - so(0)
  Eigen::Vector3d control_start = Eigen::Vector3d::Zero();   // so(0)

  int node_count() const { return static_cast<int>(rest_positions.size()); }
  int element_count() const { return static_cast<int>(elements.size()); }
  int dof_count() const { return 3 * node_count(); }
};

// The elastic model of a mesh (no springs, no gravity, no damping, dt 0.01 unless set after).
Model make_model(const Mesh& mesh, const Material& material);

// The full model of a scenario: mesh, material, damping, gravity, dt, solver, the ligaments
// with their initial stiffness, the control spring, and the physics effects it declares.
Model make_model(const Scenario& scenario);

// The rest state of the tetrahedron with these corners (world coordinates, positively
// oriented): rest-frame shape-function gradients, volume and the Lame terms.
ElementRest element_rest_state(const std::array<double, 12>& corners, const Material& material);

// The rest stiffness K_e = V B^T D B (12 x 12, isotropic linear elasticity, engineering shear
// strains) of the tetrahedron with these corners, in the coordinates the corners are given
// in. Formed explicitly only to check the factored product of element.h in the tests.
Eigen::Matrix<double, 12, 12> element_rest_stiffness(const std::array<double, 12>& corners,
                                                     const Material& material);

// Lame coefficients (lambda, mu) of an isotropic material.
Eigen::Vector2d lame_coefficients(const Material& material);

}  // namespace sigmafem
