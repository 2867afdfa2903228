// NestedMultigrid (host/reference/nested_multigrid.h): the refinements of a scenario's mesh
// are found again and interpolate linear fields exactly; a mesh that was not refined has none;
// the V-cycle is a symmetric positive definite operator (CG needs one) and takes CG on the
// refined liver's system to the tolerance in a fifth of Jacobi's iterations or fewer, with the
// coarsest level inverted or smoothed; a sigma point's own springs, given as a shift, help.
#include "host/reference/nested_multigrid.h"

#include <gtest/gtest.h>

#include "host/reference/conjugate_gradient.h"
#include "host/reference/reference_simulation.h"
#include "host/scenario/scenario.h"
#include "tests/refined_liver.h"

namespace sigmafem {
namespace {

constexpr double kMultigridCgTolerance = 1e-6;   // the float devices' CG tolerance (kSingleCgTolerance)
constexpr int kMultigridCgMaxIterations = 5000;

Model nested_liver_model(int refine) { return make_model(test::refined_liver(refine)); }

// A right-hand side with every frequency in it, the same in every run.
Eigen::VectorXd mixed_right_hand_side(Eigen::Index rows) {
  Eigen::VectorXd b(rows);
  for (Eigen::Index i = 0; i < rows; ++i) b[i] = std::sin(0.37 * static_cast<double>(i)) + 0.1 * static_cast<double>(i % 5);
  return b;
}

int pcg_iterations(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b,
                  const std::function<void(const Eigen::VectorXd&, Eigen::VectorXd&)>& precondition) {
  const auto apply = [&](const Eigen::VectorXd& x, Eigen::VectorXd& y) { y = A * x; };
  Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
  const CgResult result = preconditioned_conjugate_gradient(apply, precondition, b, x, kMultigridCgMaxIterations, kMultigridCgTolerance);
  EXPECT_TRUE(result.converged);
  return result.iterations;
}

int jacobi_cg_iterations(const Eigen::SparseMatrix<double>& A, const Eigen::VectorXd& b) {
  const Eigen::VectorXd inverse = A.diagonal().cwiseInverse();
  return pcg_iterations(A, b, [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) { z = inverse.cwiseProduct(r); });
}

TEST(NestedProlongations, TwoRefinementsAreFoundAgainAndInterpolateLinearFieldsExactly) {
  const Model coarse = nested_liver_model(0), fine = nested_liver_model(2);
  EXPECT_TRUE(nested_prolongations(coarse).empty()) << "liver.msh itself is not a refinement";
  const std::vector<RowMajorMatrix> P = nested_prolongations(fine);
  ASSERT_EQ(P.size(), 2u);
  EXPECT_EQ(P[0].rows(), fine.dof_count());
  EXPECT_EQ(P[1].cols(), coarse.dof_count());
  // The coarsest nodes' positions, interpolated twice, are the fine mesh's (x is linear).
  Eigen::VectorXd x(coarse.dof_count()), fine_x(fine.dof_count());
  for (int i = 0; i < coarse.node_count(); ++i) x.segment<3>(3 * i) = coarse.rest_positions[static_cast<std::size_t>(i)];
  for (int i = 0; i < fine.node_count(); ++i) fine_x.segment<3>(3 * i) = fine.rest_positions[static_cast<std::size_t>(i)];
  EXPECT_LE((P[0] * (P[1] * x) - fine_x).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(NestedProlongations, ElementsOutOfTheRefinementsOrderAreNotTakenForOne) {
  Model fine = nested_liver_model(1);
  std::swap(fine.elements[3], fine.elements[11]);   // a corner child into another parent's eight
  EXPECT_TRUE(nested_prolongations(fine).empty());
  Model moved = nested_liver_model(1);
  moved.rest_positions.back() += Eigen::Vector3d(1e-4, 0.0, 0.0);   // a midpoint off its edge
  EXPECT_TRUE(nested_prolongations(moved).empty());
}

class NestedMultigridTest : public ::testing::Test {
 protected:
  void SetUp() override {
    model_ = nested_liver_model(1);
    ReferenceSimulation simulation(model_);
    A_ = simulation.system_matrix();
    b_ = mixed_right_hand_side(A_.rows());
  }
  Model model_;
  Eigen::SparseMatrix<double> A_;
  Eigen::VectorXd b_;
};

TEST_F(NestedMultigridTest, TheVCycleIsSymmetricAndPositiveDefinite) {
  NestedMultigrid multigrid(nested_prolongations(model_));
  ASSERT_TRUE(multigrid.set_matrix(A_));
  ASSERT_EQ(multigrid.level_count(), 2);
  EXPECT_EQ(multigrid.coarsest_inverse().rows(), 3 * 181);   // liver.msh's nodes, inverted
  Eigen::VectorXd u = mixed_right_hand_side(A_.rows()), v = Eigen::VectorXd::LinSpaced(A_.rows(), -1.0, 2.0), Mu, Mv;
  multigrid(u, Mu);
  multigrid(v, Mv);
  EXPECT_NEAR(v.dot(Mu), u.dot(Mv), 1e-10 * std::abs(u.dot(Mv)));
  EXPECT_GT(u.dot(Mu), 0.0);
  EXPECT_GT(v.dot(Mv), 0.0);
}

TEST_F(NestedMultigridTest, CgTakesAFifthOfJacobisIterationsOrFewerInvertedOrSmoothedAtTheCoarsest) {
  const int jacobi = jacobi_cg_iterations(A_, b_);
  for (int dense_rows : {NestedMultigrid::kDenseCoarsestRows, 0}) {
    NestedMultigrid multigrid(nested_prolongations(model_), dense_rows);
    ASSERT_TRUE(multigrid.set_matrix(A_));
    const int cycles = pcg_iterations(A_, b_, [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) { multigrid(r, z); });
    // Measured: Jacobi 328, the V-cycle 18 (inverted) and 22 (smoothed).
    EXPECT_LE(5 * cycles, jacobi) << "coarsest inverted up to " << dense_rows << " rows";
    EXPECT_GT(multigrid.setup_in_cycles(), 1.0);
  }
}

TEST_F(NestedMultigridTest, ASigmaPointsOwnSpringsAsAShiftHelpItsSolve) {
  // The sigma point's ligaments five times the representative's: its matrix differs at their
  // rows' diagonal only.
  ReferenceSimulation own(model_);
  std::vector<double> stiffness = own.ligament_stiffness();
  for (double& k : stiffness) k *= 5.0;
  own.set_ligament_stiffness(stiffness);
  const Eigen::SparseMatrix<double> A_own = own.system_matrix();
  const Eigen::VectorXd shift = A_own.diagonal() - A_.diagonal();
  ASSERT_GT(shift.maxCoeff(), 0.0);
  EXPECT_LE((Eigen::SparseMatrix<double>(A_own - A_) - Eigen::SparseMatrix<double>(shift.asDiagonal())).norm(),
            1e-9 * A_.norm());
  NestedMultigrid multigrid(nested_prolongations(model_));
  ASSERT_TRUE(multigrid.set_matrix(A_));
  const int plain = pcg_iterations(A_own, b_, [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) { multigrid(r, z); });
  const int shifted = pcg_iterations(A_own, b_, [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) { multigrid(r, z, shift); });
  EXPECT_LT(shifted, plain);   // measured: 32 -> 23
}

TEST_F(NestedMultigridTest, AMatrixThatIsNotPositiveDefiniteIsRefused) {
  NestedMultigrid multigrid(nested_prolongations(model_));
  EXPECT_FALSE(multigrid.set_matrix(Eigen::SparseMatrix<double>(-A_)));
  EXPECT_FALSE(multigrid.ready());
  Eigen::VectorXd z;
  EXPECT_THROW(multigrid(b_, z), std::logic_error);
}

}  // namespace
}  // namespace sigmafem
