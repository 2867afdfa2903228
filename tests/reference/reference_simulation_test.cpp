// ReferenceSimulation (host/reference/reference_simulation) over one and many steps: one step
// is the design notes' linearised implicit Euler step, built here from its parts; damping
// only removes energy; internal forces conserve momentum (and mass damping removes it at the
// exact discrete rate); CG and the direct solve give the same trajectory.
#include "host/reference/reference_simulation.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "host/model/model.h"
#include "host/reference/corotational.h"
#include "tests/reference/structured_mesh.h"

namespace sigmafem {
namespace {

// One step rebuilt from its parts vs ReferenceSimulation::step (direct solve on both sides):
// the same equations solved by a dense and a sparse factorisation (measured 1.3e-14).
constexpr double kStepTolerance = 1e-10;
// Energy may not rise from one step to the next; rounding of the energy sum (~1e-15 of it)
// is all the slack allowed.
constexpr double kEnergyRiseSlack = 1e-12;
// Momentum: the internal forces cancel in the sum to rounding, ~1e-16 of the individual
// momenta per step (direct solve; measured 4e-15 after 100 steps); CG leaves a residual of
// 1e-13 |b| whose sum over nodes is the drift it allows (measured 3e-13).
constexpr double kMomentumDirectTolerance = 1e-12;
constexpr double kMomentumCgTolerance = 1e-10;
constexpr double kMomentumCgResidual = 1e-13;
// CG at 1e-12 relative residual per step vs the direct solve: the difference is ~cond(A) 1e-12
// per step at most, carried along the trajectory (measured 3e-13 of the motion).
constexpr double kCgTrajectoryResidual = 1e-12;
constexpr double kTrajectoryAgreement = 1e-8;

// A free body: the held box without its springs and gravity.
Model free_box_model(const test::HeldBox& held, const Damping& damping) {
  Model model = held.model;
  model.ligaments.clear();
  model.control.nodes.clear();
  model.control.stiffness = 0.0;
  model.gravity.setZero();
  model.damping = damping;
  return model;
}

// The strain energy of the co-rotational model, sum over elements of 1/2 u^T K_e u with
// u_c = R^T (x_c - x_0) - (X_c - X_0) (the corners' displacement seen in the element's rest
// frame, translation removed; K_e ignores translations) and K_e the explicit V B^T D B of
// host/model: independent of the factored element math that computes the forces.
double strain_energy(const Model& model, const Eigen::VectorXd& x) {
  std::vector<Frame> frames;
  element_frames(model, x, frames);
  double energy = 0.0;
  for (int e = 0; e < model.element_count(); ++e) {
    const ElementRest& element = model.elements[e];
    std::array<double, 12> corners{};
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 3; ++k) corners[3 * c + k] = model.rest_positions[element.nodes[c]][k];
    const Eigen::Matrix3d R = element_rotation(model, frames, e);
    Eigen::Matrix<double, 12, 1> u;
    const Eigen::Vector3d x0 = x.segment<3>(3 * element.nodes[0]);
    const Eigen::Vector3d& X0 = model.rest_positions[element.nodes[0]];
    for (int c = 0; c < 4; ++c)
      u.segment<3>(3 * c) = R.transpose() * (x.segment<3>(3 * element.nodes[c]) - x0) -
                            (model.rest_positions[element.nodes[c]] - X0);
    energy += 0.5 * u.dot(element_rest_stiffness(corners, model.material) * u);
  }
  return energy;
}

Eigen::Vector3d momentum(const Model& model, const Eigen::VectorXd& v) {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (int n = 0; n < model.node_count(); ++n) p += model.mass[n] * v.segment<3>(3 * n);
  return p;
}

// sum_i m_i |v_i|: the size of the individual momenta, against which rounding counts.
double momentum_scale(const Model& model, const Eigen::VectorXd& v) {
  double scale = 0.0;
  for (int n = 0; n < model.node_count(); ++n) scale += model.mass[n] * v.segment<3>(3 * n).norm();
  return scale;
}

TEST(ReferenceSimulationTest, OneStepIsTheLinearisedImplicitEulerStep) {
  // ARCHITECTURE.md: (M + h B + h^2 K) dv = h (f(x_n) - B v_n - h K v_n), v += dv, x += h v,
  // with B = a K + b M, K the elastic tangent plus each spring's k/n on its nodes, and f the
  // elastic force, the ligaments pulling to rest, the control spring pulling towards
  // rest + so(t_{n+1}) - so(0), and gravity.
  const test::HeldBox held = test::held_box();
  const Model& model = held.model;
  ReferenceSimulation simulation(model);
  simulation.set_linear_solver(LinearSolver::direct);
  constexpr int kSteps = 10;
  for (int step = 1; step <= kSteps; ++step) simulation.step(test::held_box_so(model, step * model.dt));
  const Eigen::VectorXd x = simulation.positions(), v = simulation.velocities();
  const Eigen::Vector3d so = test::held_box_so(model, (kSteps + 1) * model.dt);

  const double h = model.dt, a = model.damping.rayleigh_stiffness, b = model.damping.rayleigh_mass;
  std::vector<Frame> frames;
  element_frames(model, x, frames);
  Eigen::MatrixXd K(assemble_element_stiffness(model, frames));
  Eigen::VectorXd f = Eigen::VectorXd::Zero(model.dof_count());
  add_element_forces(model, frames, x, f);
  Eigen::VectorXd mass(model.dof_count());
  for (int n = 0; n < model.node_count(); ++n) {
    mass.segment<3>(3 * n).setConstant(model.mass[n]);
    f.segment<3>(3 * n) += model.mass[n] * model.gravity;
  }
  const SpringSet& ligament = model.ligaments[0];
  const double k_ligament = ligament.stiffness / static_cast<double>(ligament.nodes.size());
  for (int n : ligament.nodes) {
    f.segment<3>(3 * n) -= k_ligament * (x.segment<3>(3 * n) - model.rest_positions[n]);
    K.block<3, 3>(3 * n, 3 * n) += k_ligament * Eigen::Matrix3d::Identity();
  }
  const double k_control = model.control.stiffness / static_cast<double>(model.control.nodes.size());
  for (int n : model.control.nodes) {
    const Eigen::Vector3d target = model.rest_positions[n] + so - model.control_start;
    f.segment<3>(3 * n) -= k_control * (x.segment<3>(3 * n) - target);
    K.block<3, 3>(3 * n, 3 * n) += k_control * Eigen::Matrix3d::Identity();
  }
  const Eigen::MatrixXd M = mass.asDiagonal();
  const Eigen::MatrixXd B = a * K + b * M;
  const Eigen::VectorXd dv = (M + h * B + h * h * K).ldlt().solve(h * (f - B * v - h * K * v));
  const Eigen::VectorXd v_next = v + dv;
  const Eigen::VectorXd x_next = x + h * v_next;

  simulation.step(so);
  EXPECT_LE((simulation.velocities() - v_next).norm(), kStepTolerance * dv.norm())
      << "velocity after one step vs the implicit Euler step built from its parts";
  EXPECT_LE((simulation.positions() - x_next).norm(), kStepTolerance * h * v_next.norm())
      << "positions after one step vs the implicit Euler step built from its parts";
}

TEST(ReferenceSimulationTest, DampedFreeMotionLosesEnergyEveryStep) {
  // A free, deformed and moving body (no springs, no gravity, no load). What damping
  // guarantees is that the mechanical energy, kinetic plus strain, never rises: implicit
  // Euler on a linear system loses 1/2 |dv|_M^2 + 1/2 |dx|_K^2 + h v^T B v per step. The
  // kinetic energy alone does not decay monotonically here (strain energy turns back into
  // motion within each oscillation), so it is the total that is checked. The small amplitude
  // (strain ~1e-2) keeps the co-rotational model close to that linear analysis.
  const test::HeldBox held = test::held_box();
  const Model model = free_box_model(held, Damping{0.05, 0.2});
  ReferenceSimulation simulation(model);
  simulation.set_linear_solver(LinearSolver::direct);
  std::mt19937 random(8u);
  const Eigen::VectorXd rest = test::flat_positions(held.box.mesh);
  simulation.set_state(rest + test::random_vector(random, rest.size(), 2e-4),
                       test::random_vector(random, rest.size(), 0.01));
  double energy = simulation.kinetic_energy() + strain_energy(model, simulation.positions());
  const double initial = energy;
  ASSERT_GT(strain_energy(model, simulation.positions()), 0.0) << "initial strain energy";
  constexpr int kSteps = 200;
  for (int step = 1; step <= kSteps; ++step) {
    simulation.step(Eigen::Vector3d::Zero());
    const double next = simulation.kinetic_energy() + strain_energy(model, simulation.positions());
    ASSERT_LE(next, energy + kEnergyRiseSlack * initial)
        << "kinetic + strain energy rose at step " << step;
    energy = next;
  }
  // Not vacuous: 2 s of damping removes almost all of it.
  constexpr double kRemainingEnergy = 1e-3;
  EXPECT_LT(energy, kRemainingEnergy * initial) << "energy left after " << kSteps << " steps";
}

TEST(ReferenceSimulationTest, DampedSpinningBodyLosesKineticEnergyMonotonically) {
  // A free body set spinning (6 rad/s) and drifting as a rigid body. The co-rotational forces
  // stay near zero (a linear FEM would see large spurious strain and throw the body apart);
  // what strain the first-order position update x += h v creates is small, so the kinetic
  // energy, taken away by mass damping, decays monotonically.
  const test::HeldBox held = test::held_box();
  const Model model = free_box_model(held, Damping{0.01, 0.5});
  ReferenceSimulation simulation(model);
  const Eigen::VectorXd rest = test::flat_positions(held.box.mesh);
  const Eigen::Vector3d omega(0.0, 0.0, 6.0), drift(0.02, -0.01, 0.0), centre(0.05, 0.03, 0.02);
  Eigen::VectorXd v(rest.size());
  for (Eigen::Index n = 0; n < rest.size() / 3; ++n)
    v.segment<3>(3 * n) = drift + omega.cross(Eigen::Vector3d(rest.segment<3>(3 * n)) - centre);
  simulation.set_state(rest, v);
  double kinetic = simulation.kinetic_energy();
  constexpr int kSteps = 300;
  for (int step = 1; step <= kSteps; ++step) {
    ASSERT_TRUE(simulation.step(Eigen::Vector3d::Zero()).converged) << "CG at step " << step;
    ASSERT_LT(simulation.kinetic_energy(), kinetic) << "kinetic energy rose at step " << step;
    kinetic = simulation.kinetic_energy();
  }
}

TEST(ReferenceSimulationTest, RigidTranslationDecaysAtTheExactDiscreteRate) {
  // A rigid translation strains nothing and K v = 0, so one step is (1 + h b) M dv = -h b M v:
  // v <- v / (1 + h b) exactly, and the kinetic energy falls by (1 + h b)^2 every step.
  const test::HeldBox held = test::held_box();
  const Model model = free_box_model(held, Damping{0.05, 0.5});
  ReferenceSimulation simulation(model);
  simulation.set_linear_solver(LinearSolver::direct);
  const Eigen::VectorXd rest = test::flat_positions(held.box.mesh);
  const Eigen::Vector3d velocity(0.3, -0.1, 0.2);
  simulation.set_state(rest, test::rigidly_moved(Eigen::VectorXd::Zero(rest.size()),
                                                 Eigen::Matrix3d::Identity(), velocity));
  const double factor = 1.0 / (1.0 + model.dt * model.damping.rayleigh_mass);
  double kinetic = simulation.kinetic_energy();
  for (int step = 1; step <= 20; ++step) {
    simulation.step(Eigen::Vector3d::Zero());
    EXPECT_NEAR(simulation.kinetic_energy() / kinetic, factor * factor, kStepTolerance)
        << "kinetic energy ratio of one step of a rigid translation, step " << step;
    kinetic = simulation.kinetic_energy();
  }
}

TEST(ReferenceSimulationTest, InternalForcesConserveMomentum) {
  // No springs, no gravity: the elastic and stiffness-damping forces of every element sum to
  // zero (1^T K = 0), so summing the step's equation over the nodes leaves
  // (1 + h b) dP = -h b P: momentum is conserved for b = 0 and divided by (1 + h b) each step
  // otherwise. Deformed and moving randomly (not rigidly) from the start.
  const test::HeldBox held = test::held_box();
  const Eigen::VectorXd rest = test::flat_positions(held.box.mesh);
  for (const double b : {0.0, 0.5}) {
    for (const LinearSolver solver : {LinearSolver::direct, LinearSolver::conjugate_gradient}) {
      const bool direct = solver == LinearSolver::direct;
      Model model = free_box_model(held, Damping{0.05, b});
      model.solver.cg_tolerance = kMomentumCgResidual;
      model.solver.cg_max_iterations = 5000;
      ReferenceSimulation simulation(model);
      simulation.set_linear_solver(solver);
      std::mt19937 random(2u);
      simulation.set_state(rest + test::random_vector(random, rest.size(), 1e-3),
                           test::random_vector(random, rest.size(), 0.05));
      Eigen::Vector3d expected = momentum(model, simulation.velocities());
      const double scale = momentum_scale(model, simulation.velocities());
      const double tolerance = direct ? kMomentumDirectTolerance : kMomentumCgTolerance;
      for (int step = 1; step <= 100; ++step) {
        ASSERT_TRUE(simulation.step(Eigen::Vector3d::Zero()).converged) << "solve at step " << step;
        expected /= 1.0 + model.dt * b;
        ASSERT_LE((momentum(model, simulation.velocities()) - expected).norm(), tolerance * scale)
            << "total momentum sum m v vs P_0 / (1 + h b)^n at step " << step << ", b = " << b
            << ", " << (direct ? "direct" : "CG") << " solve";
      }
    }
  }
}

TEST(ReferenceSimulationTest, ConjugateGradientAndDirectSolveGiveTheSameTrajectory) {
  test::HeldBox held = test::held_box();
  held.model.solver.cg_tolerance = kCgTrajectoryResidual;
  held.model.solver.cg_max_iterations = 2000;
  ReferenceSimulation cg(held.model), direct(held.model);
  direct.set_linear_solver(LinearSolver::direct);
  const Eigen::VectorXd rest = test::flat_positions(held.box.mesh);
  constexpr int kSteps = 100;
  for (int step = 1; step <= kSteps; ++step) {
    const Eigen::Vector3d so = test::held_box_so(held.model, step * held.model.dt);
    const CgResult result = cg.step(so);
    ASSERT_TRUE(result.converged) << "CG at step " << step << ": relative residual "
                                  << result.relative_residual;
    direct.step(so);
    const double motion = (direct.positions() - rest).norm();
    ASSERT_LE((cg.positions() - direct.positions()).norm(), kTrajectoryAgreement * motion)
        << "positions along the CG trajectory vs the direct one, step " << step;
    ASSERT_LE((cg.velocities() - direct.velocities()).norm(),
              kTrajectoryAgreement * direct.velocities().norm())
        << "velocities along the CG trajectory vs the direct one, step " << step;
  }
}

// Known problem, disabled until decided (reported with this suite): mesh.h keeps nodes that no
// tetrahedron uses, so that node indices stay those of the file, but such a node has no mass
// and no stiffness: its row of M + h B + h^2 K is zero, the Jacobi inverse diagonal is
// 1 / 0, CG turns NaN and step() throws "positions or velocities became non-finite"; the
// direct solve throws "not positive definite". Expected once fixed (inert dofs keep dv = 0,
// e.g. a zero inverse diagonal in CG and a unit pivot in the direct solve, in every back end;
// or the loader rejects such meshes and this test goes): the extra node changes nothing.
TEST(ReferenceSimulationTest, ANodeNoTetrahedronUsesDoesNotBreakTheStep) {
  const test::HeldBox held = test::held_box();
  Mesh mesh = held.box.mesh;
  mesh.nodes.emplace_back(1.0, 1.0, 1.0);   // used by no tetrahedron
  Model model = make_model(mesh, held.model.material);
  model.damping = held.model.damping;
  model.gravity = held.model.gravity;
  model.dt = held.model.dt;
  model.ligaments = held.model.ligaments;
  model.control = held.model.control;
  model.control_start = held.model.control_start;
  for (const LinearSolver solver : {LinearSolver::conjugate_gradient, LinearSolver::direct}) {
    ReferenceSimulation with_extra(model), without(held.model);
    with_extra.set_linear_solver(solver);
    without.set_linear_solver(solver);
    for (int step = 1; step <= 5; ++step) {
      const Eigen::Vector3d so = test::held_box_so(model, step * model.dt);
      ASSERT_NO_THROW(with_extra.step(so)) << "step " << step << " with a node no tetrahedron uses";
      without.step(so);
    }
    const Eigen::Index n = without.positions().size();
    EXPECT_LE((with_extra.positions().head(n) - without.positions()).norm(),
              kStepTolerance * (without.positions() - test::flat_positions(held.box.mesh)).norm())
        << "positions with an unused node vs without it";
    EXPECT_EQ(with_extra.node_position(mesh.node_count() - 1), mesh.nodes.back())
        << "the unused node must stay where it is";
  }
}

}  // namespace
}  // namespace sigmafem
