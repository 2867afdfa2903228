// SupernodalFactor (host/reference/supernodal_factor.h) solves as the factor it regroups, to
// the precision of its float values, and groups at least each node's three columns; and
// FactorisedPreconditioner keeps the ordering (AMD or METIS) with fewer entries in the factor.
#include "host/reference/supernodal_factor.h"

#include <gtest/gtest.h>

#include <Eigen/SparseCholesky>
#include <iostream>   // Eigen's MetisSupport uses std::cerr without including it
#include <Eigen/MetisSupport>

#include "host/reference/factorised_preconditioner.h"
#include "host/reference/reference_simulation.h"
#include "tests/reference/structured_mesh.h"

namespace sigmafem {
namespace {

// The held box's implicit-Euler matrix after a few steps of deformation.
Eigen::SparseMatrix<double> box_system() {
  const test::HeldBox held = test::held_box();
  ReferenceSimulation simulation(held.model);
  for (int step = 1; step <= 5; ++step) simulation.step(test::held_box_so(held.model, step * held.model.dt));
  return simulation.system_matrix();
}

TEST(SupernodalFactor, SolvesAsTheColumnFactorItRegroupsToFloatPrecision) {
  const Eigen::SparseMatrix<double> A = box_system();
  const Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::NaturalOrdering<int>> llt(A);
  ASSERT_EQ(llt.info(), Eigen::Success);
  SupernodalFactor factor;
  factor.assign(llt.matrixL().nestedExpression());
  ASSERT_EQ(factor.size(), A.rows());
  // A node's three displacement columns have the same pattern (in the natural order too).
  EXPECT_LE(3 * factor.supernodes(), static_cast<std::size_t>(A.rows()));
  const Eigen::VectorXd r = Eigen::VectorXd::LinSpaced(A.rows(), -1.0, 2.0);
  Eigen::VectorXd z = r;
  factor.solve(z);
  const Eigen::VectorXd exact = llt.solve(r);
  // Float values (6e-8 relative) times the condition number (~1e3): 1e-4. Measured: ~1e-7.
  EXPECT_LE((z - exact).norm(), 1e-4 * exact.norm());
  EXPECT_GT(factor.bytes(), 0.0);
}

TEST(SupernodalFactor, ADenseFactorIsOneSupernode) {
  // A full SPD matrix: every column's pattern is the rest of the matrix, so one block.
  const int n = 7;
  Eigen::MatrixXd dense = Eigen::MatrixXd::Constant(n, n, 1.0) + n * Eigen::MatrixXd::Identity(n, n);
  const Eigen::SparseMatrix<double> A = dense.sparseView();
  const Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::NaturalOrdering<int>> llt(A);
  SupernodalFactor factor;
  factor.assign(llt.matrixL().nestedExpression());
  EXPECT_EQ(factor.supernodes(), 1u);
  Eigen::VectorXd z = Eigen::VectorXd::Ones(n);
  factor.solve(z);
  EXPECT_LE((dense * z - Eigen::VectorXd::Ones(n)).norm(), 1e-6);
}

TEST(FactorisedPreconditioner, KeepsTheOrderingWithFewerEntriesInTheFactor) {
  // The box (small: AMD's fill is about METIS's) and a 3D grid Laplacian of 14^3 nodes, where
  // nested dissection leaves markedly fewer entries than minimum degree.
  Eigen::SparseMatrix<double> grid;
  {
    const int m = 14;
    const auto index = [&](int i, int j, int k) { return (i * m + j) * m + k; };
    std::vector<Eigen::Triplet<double>> entries;
    for (int i = 0; i < m; ++i)
      for (int j = 0; j < m; ++j)
        for (int k = 0; k < m; ++k) {
          entries.emplace_back(index(i, j, k), index(i, j, k), 6.1);
          if (i + 1 < m) entries.emplace_back(index(i + 1, j, k), index(i, j, k), -1.0);
          if (j + 1 < m) entries.emplace_back(index(i, j + 1, k), index(i, j, k), -1.0);
          if (k + 1 < m) entries.emplace_back(index(i, j, k + 1), index(i, j, k), -1.0);
        }
    grid.resize(m * m * m, m * m * m);
    grid.setFromTriplets(entries.begin(), entries.end());   // the lower triangle
  }
  const Eigen::SparseMatrix<double> box = box_system();
  const Eigen::SparseMatrix<double>* const matrices[] = {&box, &grid};
  for (const Eigen::SparseMatrix<double>* A_pointer : matrices) {
    const Eigen::SparseMatrix<double>& A = *A_pointer;
    const Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> amd(A);
    const Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::MetisOrdering<int>> metis(A);
    const Eigen::Index fewest = std::min(amd.matrixL().nestedExpression().nonZeros(),
                                         metis.matrixL().nestedExpression().nonZeros());
    FactorisedPreconditioner factor;
    ASSERT_TRUE(factor.factorise(A));
    EXPECT_EQ(static_cast<Eigen::Index>(factor.nonzeros()), fewest)
        << "AMD " << amd.matrixL().nestedExpression().nonZeros() << ", METIS "
        << metis.matrixL().nestedExpression().nonZeros();
    if (A_pointer == &grid) {
      EXPECT_LT(metis.matrixL().nestedExpression().nonZeros(), amd.matrixL().nestedExpression().nonZeros())
          << "the grid is the case where METIS is kept";
    }
  }
}

}  // namespace
}  // namespace sigmafem
