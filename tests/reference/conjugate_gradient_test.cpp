// conjugate_gradient (host/reference/conjugate_gradient.h): the same answer as Eigen's
// Jacobi-preconditioned CG and as the direct solve on the implicit Euler system of a
// deformed, moving organ, and honest statuses at its edges (the cap, b = 0, a converged warm
// start, a non-finite operator).
#include "host/reference/conjugate_gradient.h"

#include <gtest/gtest.h>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "host/reference/implicit_euler.h"
#include "host/reference/reference_simulation.h"
#include "tests/reference/structured_mesh.h"

namespace sigmafem {
namespace {

// Both CGs run to a relative residual of 1e-12; the implicit Euler matrix's condition number
// is at most ~1e3 here, so each solution is within ~1e-9 of the exact one (measured: 1e-15
// apart, and from the direct solve).
constexpr double kSolveTolerance = 1e-12;
constexpr double kAgreement = 1e-8;
// Same preconditioner (1 / diag A) and the same stopping rule (|r| <= tol |b|): the iterates
// are the same up to rounding, so the counts may differ only where rounding moves the
// residual across the threshold, by an iteration or two (measured: 179 vs 178).
constexpr int kIterationCountSlack = 2;
// The residual CG reports is its recurrence r -= alpha A d, which drifts from the true
// b - A x by rounding only, ~1e-15 of |b|; far below the capped residual, so 1e-6 of it.
constexpr double kReportedResidualAgreement = 1e-6;
// A looser tolerance than the one the warm start was solved to: it must already be met.
constexpr double kLooseTolerance = 1e-8;
constexpr int kMaxIterations = 2000;     // ~20x what the system needs
constexpr int kCgWarmUpSteps = 30;

class ConjugateGradientTest : public ::testing::Test {
 protected:
  void SetUp() override {
    held_ = test::held_box();
    const Model& model = held_.model;
    ReferenceSimulation simulation(model);
    for (int step = 1; step <= kCgWarmUpSteps; ++step)
      ASSERT_TRUE(simulation.step(test::held_box_so(model, step * model.dt)).converged)
          << "CG of warm-up step " << step;
    x_ = simulation.positions();
    element_frames(model, x_, frames_);
    springs_ = simulation.node_springs();
    system_ = std::make_unique<ImplicitEulerSystem>(model, frames_, springs_);
    b_ = system_->right_hand_side(
        simulation.forces(x_, frames_, test::held_box_so(model, (kCgWarmUpSteps + 1) * model.dt)),
        simulation.velocities());
    inverse_diagonal_ = system_->diagonal().cwiseInverse();
  }

  test::HeldBox held_;
  Eigen::VectorXd x_, springs_, b_, inverse_diagonal_;
  std::vector<Frame> frames_;
  std::unique_ptr<ImplicitEulerSystem> system_;
};

TEST_F(ConjugateGradientTest, AgreesWithEigenConjugateGradientAndTheDirectSolve) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(b_.size());
  const CgResult result =
      conjugate_gradient(*system_, inverse_diagonal_, b_, x, kMaxIterations, kSolveTolerance);
  ASSERT_TRUE(result.converged) << "CG status on the implicit Euler system: relative residual "
                                << result.relative_residual << " after " << result.iterations;
  EXPECT_LE(result.relative_residual, kSolveTolerance) << "reported relative residual";
  Eigen::VectorXd Ax;
  system_->apply(x, Ax);
  EXPECT_LE((b_ - Ax).norm(), kSolveTolerance * b_.norm())
      << "true relative residual |b - A x| / |b| at exit";

  const Eigen::SparseMatrix<double> A = system_->assemble(AssemblyPattern(held_.model));
  // DiagonalPreconditioner is Eigen's default: Jacobi, as ours.
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                           Eigen::DiagonalPreconditioner<double>>
      eigen_cg(A);
  eigen_cg.setTolerance(kSolveTolerance);
  eigen_cg.setMaxIterations(kMaxIterations);
  const Eigen::VectorXd x_eigen = eigen_cg.solve(b_);
  ASSERT_EQ(eigen_cg.info(), Eigen::Success) << "Eigen::ConjugateGradient status";
  EXPECT_LE((x - x_eigen).norm(), kAgreement * x_eigen.norm())
      << "solution vs Eigen::ConjugateGradient on the assembled matrix";
  const Eigen::VectorXd x_direct = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>(A).solve(b_);
  EXPECT_LE((x - x_direct).norm(), kAgreement * x_direct.norm())
      << "solution vs the LDLT solve of the assembled matrix";
  EXPECT_NEAR(result.iterations, static_cast<int>(eigen_cg.iterations()), kIterationCountSlack)
      << "iteration count vs Eigen::ConjugateGradient's";
}

TEST_F(ConjugateGradientTest, ReportsTheCapInsteadOfHidingIt) {
  constexpr int kCap = 3;   // far fewer than the ~100 the system needs
  Eigen::VectorXd x = Eigen::VectorXd::Zero(b_.size());
  const CgResult result = conjugate_gradient(*system_, inverse_diagonal_, b_, x, kCap, kSolveTolerance);
  EXPECT_FALSE(result.converged) << "convergence status after hitting the cap";
  EXPECT_EQ(result.iterations, kCap) << "iterations done when capped";
  EXPECT_GT(result.relative_residual, kSolveTolerance) << "relative residual when capped";
  EXPECT_TRUE(std::isfinite(result.relative_residual)) << "relative residual when capped";
  // The reported residual is the true one of the x returned.
  Eigen::VectorXd Ax;
  system_->apply(x, Ax);
  EXPECT_NEAR(result.relative_residual, (b_ - Ax).norm() / b_.norm(), kReportedResidualAgreement * result.relative_residual)
      << "reported vs true relative residual when capped";
}

TEST_F(ConjugateGradientTest, ReturnsAtOnceForZeroRightHandSideOrConvergedStart) {
  int products = 0;
  const auto counting = [&](const Eigen::VectorXd& d, Eigen::VectorXd& y) {
    ++products;
    system_->apply(d, y);
  };
  // b = 0: the answer is x = 0 whatever the start, without a single product.
  Eigen::VectorXd x = Eigen::VectorXd::Ones(b_.size());
  const CgResult zero = conjugate_gradient(counting, inverse_diagonal_,
                                           Eigen::VectorXd::Zero(b_.size()), x, 100, kLooseTolerance);
  EXPECT_TRUE(zero.converged) << "status for b = 0";
  EXPECT_EQ(zero.iterations, 0) << "iterations for b = 0";
  EXPECT_EQ(products, 0) << "operator products for b = 0";
  EXPECT_EQ(x.norm(), 0.0) << "solution for b = 0";

  // A start that already meets the tolerance: one product (its residual), no iteration, and
  // the start is returned untouched.
  conjugate_gradient(*system_, inverse_diagonal_, b_, x, kMaxIterations, kSolveTolerance);
  const Eigen::VectorXd solved = x;
  products = 0;
  const CgResult again = conjugate_gradient(counting, inverse_diagonal_, b_, x, kMaxIterations, kLooseTolerance);
  EXPECT_TRUE(again.converged) << "status for a converged warm start";
  EXPECT_EQ(again.iterations, 0) << "iterations for a converged warm start";
  EXPECT_EQ(products, 1) << "operator products for a converged warm start";
  EXPECT_LE(again.relative_residual, kLooseTolerance) << "relative residual reported for a converged warm start";
  EXPECT_EQ(x, solved) << "a converged warm start must be returned unchanged";
}

TEST_F(ConjugateGradientTest, StopsOnNonFiniteNumbersInsteadOfSpinning) {
  const auto broken = [](const Eigen::VectorXd& d, Eigen::VectorXd& y) {
    y = d;
    y[0] = std::numeric_limits<double>::quiet_NaN();   // a NaN in the model, say
  };
  Eigen::VectorXd x = Eigen::VectorXd::Zero(b_.size());
  const CgResult result =
      conjugate_gradient(broken, Eigen::VectorXd::Ones(b_.size()), b_, x, 1000, kLooseTolerance);
  EXPECT_FALSE(result.converged) << "status with a non-finite operator";
  EXPECT_LE(result.iterations, 1) << "iterations with a non-finite operator (must stop at the first)";
}

// An overflowed load made the stop test tol * |b| infinite, which every residual passes: the
// solve "converged" after 0 iterations with nothing solved (issue 14).
TEST_F(ConjugateGradientTest, AnInfiniteLoadIsABreakdownNotAConvergence) {
  int products = 0;
  const auto counting = [&](const Eigen::VectorXd& d, Eigen::VectorXd& y) {
    ++products;
    y = d;
  };
  Eigen::VectorXd b = b_;
  b[0] = std::numeric_limits<double>::infinity();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
  const CgResult result = conjugate_gradient(counting, Eigen::VectorXd::Ones(b.size()), b, x, 1000, kLooseTolerance);
  EXPECT_FALSE(result.converged);
  EXPECT_TRUE(std::isnan(result.relative_residual)) << "the caller can tell a breakdown from a cap";
  EXPECT_EQ(products, 0);
}

}  // namespace
}  // namespace sigmafem
