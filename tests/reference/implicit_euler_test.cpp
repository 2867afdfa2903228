// ImplicitEulerSystem (host/reference/implicit_euler): its matrix is the design notes'
// M + h B + h^2 K with B = a K + b M, in matrix-free, diagonal and assembled form alike, and
// the two ways the reference solves it (Jacobi CG and the sparse direct solve) give the same
// velocity change on the system of a deformed, moving state.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <random>
#include <vector>

#include "host/model/model.h"
#include "host/reference/conjugate_gradient.h"
#include "host/reference/corotational.h"
#include "host/reference/implicit_euler.h"
#include "host/reference/reference_simulation.h"
#include "tests/reference/structured_mesh.h"

namespace sigmafem {
namespace {

// Matrix-free product, diagonal and right-hand side vs the assembled matrix or the formula
// built here: the same terms summed in another order, ~1e-15 relative.
constexpr double kFormulaTolerance = 1e-13;
// CG is run to a relative residual of 1e-13; the matrix's condition number (at most ~1e3
// here: mass against stiffness times h (h + a)) bounds the solution's error by ~1e-10, and
// the direct solve is exact to ~1e-15. Measured difference: 2e-15 relative. 1e-8 is the
// agreement the device back ends are held to in double, with a wide margin.
constexpr double kCgTightTolerance = 1e-13;
constexpr double kSolverAgreement = 1e-8;
constexpr int kWarmUpSteps = 30;

class ImplicitEulerTest : public ::testing::Test {
 protected:
  ImplicitEulerTest() : held_(test::held_box()) {}

  // The state after kWarmUpSteps of the held box pulled by its SO: deformed, rotated a little,
  // moving. Fills x, v, frames, springs and the force at the next step's SO.
  void warm_up() {
    ReferenceSimulation simulation(held_.model);
    for (int step = 1; step <= kWarmUpSteps; ++step) {
      const CgResult result = simulation.step(test::held_box_so(held_.model, step * held_.model.dt));
      ASSERT_TRUE(result.converged) << "CG of warm-up step " << step;
    }
    x_ = simulation.positions();
    v_ = simulation.velocities();
    element_frames(held_.model, x_, frames_);
    springs_ = simulation.node_springs();
    force_ = simulation.forces(x_, frames_, test::held_box_so(held_.model, (kWarmUpSteps + 1) * held_.model.dt));
  }

  test::HeldBox held_;
  Eigen::VectorXd x_, v_, springs_, force_;
  std::vector<Frame> frames_;
  std::mt19937 random_{99u};
};

TEST_F(ImplicitEulerTest, MatrixIsMassPlusDampingPlusStiffnessAsInTheDesignNotes) {
  warm_up();
  const Model& model = held_.model;
  const ImplicitEulerSystem system(model, frames_, springs_);
  const double h = model.dt, a = model.damping.rayleigh_stiffness, b = model.damping.rayleigh_mass;
  EXPECT_DOUBLE_EQ(system.mass_factor(), 1.0 + h * b) << "mass factor 1 + h b";
  EXPECT_DOUBLE_EQ(system.stiffness_factor(), h * (h + a)) << "stiffness factor h (h + a)";

  // M, K (elastic tangent plus springs on the diagonal) and B = a K + b M, built here.
  const int n = model.dof_count();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(n, n);
  Eigen::MatrixXd K = Eigen::MatrixXd(assemble_element_stiffness(model, frames_));
  for (int node = 0; node < model.node_count(); ++node)
    for (int axis = 0; axis < 3; ++axis) {
      M(3 * node + axis, 3 * node + axis) = model.mass[node];
      K(3 * node + axis, 3 * node + axis) += springs_[node];
    }
  const Eigen::MatrixXd B = a * K + b * M;
  const Eigen::MatrixXd A = M + h * B + h * h * K;

  const Eigen::MatrixXd assembled(system.assemble(AssemblyPattern(model)));
  EXPECT_LE((assembled - A).norm(), kFormulaTolerance * A.norm())
      << "assembled implicit Euler matrix vs M + h B + h^2 K";
  const Eigen::VectorXd d = test::random_vector(random_, n);
  Eigen::VectorXd Ad, Kd;
  system.apply(d, Ad);
  EXPECT_LE((Ad - A * d).norm(), kFormulaTolerance * (A * d).norm())
      << "matrix-free product A d vs (M + h B + h^2 K) d";
  system.stiffness_product(d, Kd);
  EXPECT_LE((Kd - K * d).norm(), kFormulaTolerance * (K * d).norm())
      << "stiffness product K d (springs included)";
  EXPECT_LE((system.diagonal() - A.diagonal()).norm(), kFormulaTolerance * A.diagonal().norm())
      << "diagonal of the implicit Euler matrix";
  const Eigen::VectorXd rhs = h * (force_ - B * v_ - h * K * v_);
  EXPECT_LE((system.right_hand_side(force_, v_) - rhs).norm(), kFormulaTolerance * rhs.norm())
      << "right-hand side vs h (f - B v - h K v)";
  // Symmetric positive definite (Cholesky succeeds).
  EXPECT_LE((A - A.transpose()).norm(), kFormulaTolerance * A.norm()) << "asymmetry of A";
  EXPECT_EQ(Eigen::LLT<Eigen::MatrixXd>(A).info(), Eigen::Success)
      << "Cholesky of the implicit Euler matrix (positive definiteness)";
}

TEST_F(ImplicitEulerTest, ConjugateGradientAndDirectSolveAgreeOnADeformedState) {
  warm_up();
  const ImplicitEulerSystem system(held_.model, frames_, springs_);
  const Eigen::VectorXd rhs = system.right_hand_side(force_, v_);

  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(system.assemble(AssemblyPattern(held_.model)));
  ASSERT_EQ(ldlt.info(), Eigen::Success) << "LDLT of the implicit Euler matrix";
  const Eigen::VectorXd direct = ldlt.solve(rhs);

  Eigen::VectorXd cg = Eigen::VectorXd::Zero(rhs.size());
  const CgResult result = conjugate_gradient(system, system.diagonal().cwiseInverse(), rhs, cg,
                                             10 * static_cast<int>(rhs.size()), kCgTightTolerance);
  ASSERT_TRUE(result.converged) << "CG on the implicit Euler system: relative residual "
                                << result.relative_residual << " after " << result.iterations;
  EXPECT_LE((cg - direct).norm(), kSolverAgreement * direct.norm())
      << "velocity change by CG vs by the direct solve (" << result.iterations << " CG iterations)";
}

}  // namespace
}  // namespace sigmafem
