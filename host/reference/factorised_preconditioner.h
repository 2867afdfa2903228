// FactorisedPreconditioner: a sparse Cholesky factor (Eigen's SimplicialLLT) of an implicit-
// Euler matrix, applied as CG's preconditioner to the systems of later steps (issue 18).
// Those differ from the factorised one only by the rotations of a few steps (and, for the
// sigma points of an ensemble that share one factor, by a few spring stiffnesses), so
// M^-1 A stays close to the identity and CG needs a few iterations instead of hundreds.
// The ordering is the one of AMD and METIS's nested dissection that leaves fewer entries in
// the factor (on the 38k liver METIS: 7.6 million against 10.4, and half the time to
// factorise; on the small meshes AMD); the solves run on its supernodes in float
// (host/reference/supernodal_factor.h).
// Like SOFA's asynchronous preconditioner, the factor is kept over many steps and made again
// when it stops paying (RefreshRule, host/reference/refresh_rule.h), its work counted in
// solves with it. On the 38k liver a factorisation is the work of 320 solves (measured: 3-4 s
// against 10.6-14 ms a solve); on the liver (596 tetrahedra) of 31, on the box of 55.
// Solving with it is const and thread-safe: sigma points' threads may share one factor.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <vector>

#include "host/reference/refresh_rule.h"
#include "host/reference/supernodal_factor.h"

namespace sigmafem {

// A stand-in for L while no factorisation has succeeded (the device back ends' first steps):
// sqrt|A_ii| per row, so that solving with it is Jacobi's z = r / |diag A|. The absolute
// value because a preconditioner must be positive definite (a negative diagonal would be
// Jacobi's with the sign of the whole system turned); 1, a row left unscaled, where the
// diagonal is 0 or not finite.
std::vector<double> diagonal_stand_in(const Eigen::SparseMatrix<double>& A);

class FactorisedPreconditioner {
 public:
  // `rows_last`: rows of A ordered after all the others (each ordering is then the one of the
  // rest, these appended in increasing order). A SpringCorrection at those rows then reaches
  // only them: V = L^-1 P E is zero above its last m rows, where with the free ordering it
  // filled the rows' ancestors in the elimination tree (the liver: 27 rows against 258, for
  // 10% more entries in L; bench/RESULTS.md, stop 58).
  explicit FactorisedPreconditioner(std::vector<int> rows_last = {});
  // Factorises A (symmetric positive definite). Returns false, and leaves the object
  // unusable until the next success, when A is not positive definite.
  bool factorise(const Eigen::SparseMatrix<double>& A);
  // Orders and analyses A's pattern without factorising: the factor's size (nonzeros()) is
  // then known, and factorise() of a matrix with that pattern keeps the ordering and the
  // analysis. A is symmetric; its lower triangle is read.
  void analyse(const Eigen::SparseMatrix<double>& A);
  // Nonzeros of L (after analyse() or a factorise()).
  std::size_t nonzeros() const {
    return static_cast<std::size_t>(llt_.matrixL().nestedExpression().nonZeros());
  }
  bool ready() const { return ready_; }
  int factorisations() const { return factorisations_; }
  // Memory the factor holds (its nonzeros with their row indices, and its supernodes), 0
  // before the first.
  double bytes() const;

  // Whether to factorise before the next step (RefreshRule); not between a factorisation and
  // the record() of its first step.
  bool due() const { return refresh_.due(); }
  // The most CG iterations of a step just done with this factor.
  void record(int most_iterations) { refresh_.record(most_iterations); }
  // The work of a factorisation in solves with the factor: sum_j c_j^2 multiply-adds (c_j the
  // entries of L's column j) against the 2 nnz(L) of a solve's two substitutions.
  double factorisation_in_solves() const { return factorisation_in_solves_; }

  // The factor itself, for a device that solves with it (OpenClEnsemble): A = P^T L L^T P,
  // L lower triangular by columns with each column's diagonal entry first, P the ordering
  // (order()[i] is row i's position in L's rows). Valid while ready().
  const Eigen::SparseMatrix<double>& lower() const { return llt_.matrixL().nestedExpression(); }
  const int* order() const { return order_.indices().data(); }

  // z = A_rep^-1 r = P^T L^-T L^-1 P r, the substitutions on the factor's float supernodes.
  void operator()(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;

 private:
  using Ordering = Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>;
  bool same_pattern(const Eigen::SparseMatrix<double>& A) const;
  // A's symmetric permutation by order_, the matrix llt_ factorises (in its natural order).
  Eigen::SparseMatrix<double> ordered(const Eigen::SparseMatrix<double>& A) const;
  // For rows_last_: the other rows in increasing order (`first`, of A's n rows); A's pattern
  // on those rows alone, numbered so; an ordering of that (inverse, as the orderings give it)
  // with rows_last_ appended, of all n rows.
  std::vector<int> rows_first(Eigen::Index n) const;
  Eigen::SparseMatrix<double> without_rows_last(const Eigen::SparseMatrix<double>& whole,
                                                const std::vector<int>& first) const;
  Ordering with_rows_last(const Ordering& rest_inverse, const std::vector<int>& first) const;
  Ordering order_;
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::NaturalOrdering<int>> llt_;
  SupernodalFactor supernodes_;
  std::vector<int> outer_, inner_;   // the pattern analysed (empty: none yet)
  std::vector<int> rows_last_;
  bool ready_ = false;
  int factorisations_ = 0;
  RefreshRule refresh_;
  double factorisation_in_solves_ = 0.0;  // of the pattern analysed
};

}  // namespace sigmafem
