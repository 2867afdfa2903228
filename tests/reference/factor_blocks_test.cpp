// FactorBlocks (host/reference/factor_blocks.h): L cut into 4 x 4 blocks solves as L itself,
// with the factor's ordering and after new values of the same pattern; its panels are
// consecutive columns of one pattern below them, at most 4 wide, and each of L's entries lands
// in exactly one block or triangle; a diagonal factor is panels of 4 with no blocks.
#include "host/reference/factor_blocks.h"

#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <set>

#include "host/model/model.h"
#include "host/reference/factorised_preconditioner.h"
#include "host/reference/reference_simulation.h"
#include "host/scenario/scenario.h"
#include "tests/scenario_directory.h"

namespace sigmafem {
namespace {

Eigen::SparseMatrix<double> scenario_system(const std::string& name) {
  return ReferenceSimulation(make_model(load_scenario(kScenarios + name + ".json"))).system_matrix();
}

// x = A^-1 b through P^T L^-T L^-1 P with the blocks' solve.
Eigen::VectorXd block_solve(const FactorBlocks& blocks, const FactorisedPreconditioner& factor,
                            const Eigen::VectorXd& b) {
  const Eigen::Index n = b.size();
  Eigen::VectorXd y(n);
  for (Eigen::Index i = 0; i < n; ++i) y[factor.order()[i]] = b[i];
  blocks.solve(y);
  Eigen::VectorXd x(n);
  for (Eigen::Index i = 0; i < n; ++i) x[i] = y[factor.order()[i]];
  return x;
}

TEST(FactorBlocks, SolvesAsTheFactorOnTheBoxAndTheLiver) {
  for (const char* name : {"box", "liver"}) {
    SCOPED_TRACE(name);
    const Eigen::SparseMatrix<double> A = scenario_system(name);
    FactorisedPreconditioner factor;
    ASSERT_TRUE(factor.factorise(A));
    const FactorBlocks blocks(factor.lower(), factor.order());
    const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(A.rows(), -1.0, 2.0);
    const Eigen::VectorXd x = block_solve(blocks, factor, b);
    // Double values throughout: the residual is rounding times the condition number.
    EXPECT_LE((A * x - b).norm(), 1e-9 * b.norm());
    // Fewer blocks than entries by far: a substitution turns once a block (on the liver 2334
    // blocks for 26 088 entries).
    EXPECT_LT(4 * blocks.blocks(), static_cast<std::size_t>(factor.nonzeros()));
    EXPECT_GE(4 * blocks.panels(), A.rows());
    EXPECT_LE(3 * blocks.panels(), A.rows()) << "about a node's 3 columns a panel at least";
  }
}

TEST(FactorBlocks, EveryEntryOfLLandsInOneBlockOrItsPanelsTriangle) {
  const Eigen::SparseMatrix<double> A = scenario_system("liver");
  FactorisedPreconditioner factor;
  ASSERT_TRUE(factor.factorise(A));
  const Eigen::SparseMatrix<double>& L = factor.lower();
  const FactorBlocks blocks(L, factor.order());
  // Every slot row is an original row once, or padding.
  std::set<int> rows;
  for (const int row : blocks.slot_rows())
    if (row >= 0) {
      EXPECT_TRUE(rows.insert(row).second) << "row " << row << " in two slots";
    }
  EXPECT_EQ(rows.size(), static_cast<std::size_t>(A.rows()));
  // The blocks' and triangles' entries sum to L's (each entry placed once, nothing else).
  double in_blocks = 0.0, in_triangles = 0.0;
  for (const double v : blocks.forward_values()) in_blocks += std::abs(v);
  for (const double v : blocks.triangles()) in_triangles += std::abs(v);
  const int padding = 4 * blocks.panels() - static_cast<int>(A.rows());   // unit diagonals
  EXPECT_NEAR(in_blocks + in_triangles - padding, L.cwiseAbs().sum(), 1e-9 * L.cwiseAbs().sum());
  double backward = 0.0;
  for (const double v : blocks.backward_values()) backward += std::abs(v);
  EXPECT_NEAR(backward, in_blocks, 1e-12 * in_blocks) << "the same blocks, by columns";
  // By rows and by columns, the same (row panel, column panel) pairs, row panel below.
  std::set<std::pair<int, int>> by_rows, by_columns;
  for (int q = 0; q < blocks.panels(); ++q)
    for (int k = blocks.forward_starts()[q]; k < blocks.forward_starts()[q + 1]; ++k) {
      EXPECT_LT(blocks.forward_panel()[k], q);
      by_rows.insert({q, blocks.forward_panel()[k]});
    }
  for (int p = 0; p < blocks.panels(); ++p)
    for (int k = blocks.backward_starts()[p]; k < blocks.backward_starts()[p + 1]; ++k)
      by_columns.insert({blocks.backward_panel()[k], p});
  EXPECT_EQ(by_rows, by_columns);
  EXPECT_EQ(by_rows.size(), blocks.blocks());
}

TEST(FactorBlocks, NewValuesOfTheSamePatternSolveTheNewSystem) {
  const Eigen::SparseMatrix<double> A = scenario_system("box");
  FactorisedPreconditioner factor;
  ASSERT_TRUE(factor.factorise(A));
  FactorBlocks blocks(factor.lower(), factor.order());
  Eigen::SparseMatrix<double> stiffer = A;
  for (Eigen::Index i = 0; i < A.rows(); i += 7) stiffer.coeffRef(i, i) *= 1.5;
  ASSERT_TRUE(factor.factorise(stiffer));   // the same pattern: the analysis is kept
  ASSERT_TRUE(blocks.same_pattern(factor.lower()));
  blocks.assign_values(factor.lower());
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(A.rows());
  const Eigen::VectorXd x = block_solve(blocks, factor, b);
  EXPECT_LE((stiffer * x - b).norm(), 1e-9 * b.norm());
  EXPECT_GT((A * x - b).norm(), 1e-3 * b.norm()) << "the new values are used";
}

TEST(FactorBlocks, ADiagonalFactorIsPanelsOfFourWithoutBlocks) {
  const int n = 10;
  Eigen::SparseMatrix<double> L(n, n);
  for (int i = 0; i < n; ++i) L.insert(i, i) = 2.0 + i;
  L.makeCompressed();
  std::vector<int> identity(n);
  for (int i = 0; i < n; ++i) identity[static_cast<std::size_t>(i)] = i;
  const FactorBlocks blocks(L, identity.data());
  Eigen::SparseMatrix<double> other = L;
  other.insert(3, 1) = 0.5;
  other.makeCompressed();
  EXPECT_FALSE(blocks.same_pattern(other));
  EXPECT_THROW(FactorBlocks(blocks).assign_values(other), std::invalid_argument);
  EXPECT_EQ(blocks.panels(), 3);
  EXPECT_EQ(blocks.blocks(), 0u);
  ASSERT_EQ(blocks.slot_rows().size(), 12u);
  EXPECT_EQ(blocks.slot_rows()[8], 8);   // panel 2 holds rows 8 and 9, then padding
  EXPECT_EQ(blocks.slot_rows()[9], 9);
  EXPECT_EQ(blocks.slot_rows()[10], -1);
  EXPECT_EQ(blocks.slot_rows()[11], -1);
  Eigen::VectorXd y = Eigen::VectorXd::Ones(n);
  blocks.solve(y);
  for (int i = 0; i < n; ++i) EXPECT_DOUBLE_EQ(y[i], 1.0 / ((2.0 + i) * (2.0 + i)));
}

TEST(FactorBlocks, AFactorWhoseColumnsDoNotStartAtTheDiagonalIsRefused) {
  Eigen::SparseMatrix<double> L(2, 2);
  L.insert(1, 0) = 1.0;
  L.insert(1, 1) = 1.0;
  L.makeCompressed();
  const int order[2] = {0, 1};
  EXPECT_THROW(FactorBlocks(L, order), std::invalid_argument);
}

}  // namespace
}  // namespace sigmafem
