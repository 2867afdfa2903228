#include "host/reference/factorised_preconditioner.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <iostream>   // Eigen's MetisSupport uses std::cerr without including it
#include <Eigen/MetisSupport>

namespace sigmafem {

std::vector<double> diagonal_stand_in(const Eigen::SparseMatrix<double>& A) {
  std::vector<double> values(static_cast<std::size_t>(A.rows()));
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    const double d = std::abs(A.coeff(i, i));
    values[static_cast<std::size_t>(i)] = std::isfinite(d) && d > 0.0 ? std::sqrt(d) : 1.0;
  }
  return values;
}

bool FactorisedPreconditioner::factorise(const Eigen::SparseMatrix<double>& A) {
  // The ordering and the symbolic analysis depend only on the pattern, and cost more than a
  // numeric factorisation on the liver: made again only when the pattern changes (an
  // AssemblyPattern keeps it the same from step to step).
  if (!same_pattern(A)) analyse(A);
  llt_.factorize(ordered(A));
  ready_ = llt_.info() == Eigen::Success;
  refresh_.made(ready_, factorisation_in_solves_);
  if (ready_) {
    ++factorisations_;
    supernodes_.assign(lower());
  }
  return ready_;
}

Eigen::SparseMatrix<double> FactorisedPreconditioner::ordered(const Eigen::SparseMatrix<double>& A) const {
  Eigen::SparseMatrix<double> permuted(A.rows(), A.cols());
  permuted.selfadjointView<Eigen::Lower>() = A.selfadjointView<Eigen::Lower>().twistedBy(order_);
  return permuted;
}

FactorisedPreconditioner::FactorisedPreconditioner(std::vector<int> rows_last) : rows_last_(std::move(rows_last)) {
  std::sort(rows_last_.begin(), rows_last_.end());
  rows_last_.erase(std::unique(rows_last_.begin(), rows_last_.end()), rows_last_.end());
}

std::vector<int> FactorisedPreconditioner::rows_first(Eigen::Index n) const {
  std::vector<bool> last(static_cast<std::size_t>(n), false);
  for (int row : rows_last_) {
    if (row < 0 || row >= n) throw std::invalid_argument("FactorisedPreconditioner: a row to order last is outside A");
    last[static_cast<std::size_t>(row)] = true;
  }
  std::vector<int> first;
  for (int i = 0; i < static_cast<int>(n); ++i)
    if (!last[static_cast<std::size_t>(i)]) first.push_back(i);
  return first;
}

Eigen::SparseMatrix<double> FactorisedPreconditioner::without_rows_last(const Eigen::SparseMatrix<double>& whole,
                                                                         const std::vector<int>& first) const {
  std::vector<int> position(static_cast<std::size_t>(whole.rows()), -1);
  for (std::size_t k = 0; k < first.size(); ++k) position[static_cast<std::size_t>(first[k])] = static_cast<int>(k);
  std::vector<Eigen::Triplet<double>> entries;
  for (Eigen::Index j = 0; j < whole.outerSize(); ++j)
    for (Eigen::SparseMatrix<double>::InnerIterator it(whole, j); it; ++it) {
      const int row = position[static_cast<std::size_t>(it.row())], column = position[static_cast<std::size_t>(j)];
      if (row >= 0 && column >= 0) entries.emplace_back(row, column, it.value());
    }
  const Eigen::Index n = static_cast<Eigen::Index>(first.size());
  Eigen::SparseMatrix<double> rest(n, n);
  rest.setFromTriplets(entries.begin(), entries.end());
  return rest;
}

FactorisedPreconditioner::Ordering FactorisedPreconditioner::with_rows_last(const Ordering& rest_inverse,
                                                                            const std::vector<int>& first) const {
  Ordering inverse(static_cast<Eigen::Index>(first.size() + rows_last_.size()));
  Eigen::Index k = 0;
  for (Eigen::Index i = 0; i < rest_inverse.size(); ++i)
    inverse.indices()[k++] = first[static_cast<std::size_t>(rest_inverse.indices()[i])];
  for (int row : rows_last_) inverse.indices()[k++] = row;
  return inverse;
}

void FactorisedPreconditioner::analyse(const Eigen::SparseMatrix<double>& A) {
  // Both orderings, analysed (a symbolic factorisation: the factor's column counts), and the
  // one with fewer entries kept. The orderings give the inverse permutation (Eigen's
  // SimplicialCholesky does the same), and want the whole symmetric pattern.
  const Eigen::SparseMatrix<double> whole = A.selfadjointView<Eigen::Lower>();
  Ordering amd_inverse, metis_inverse;
  if (rows_last_.empty()) {
    Eigen::AMDOrdering<int>()(whole, amd_inverse);
    Eigen::MetisOrdering<int>()(whole, metis_inverse);
  } else {
    const std::vector<int> first = rows_first(A.rows());
    const Eigen::SparseMatrix<double> rest = without_rows_last(whole, first);
    Ordering amd_rest, metis_rest;   // empty where every row is to be last
    if (rest.rows() > 0) {
      Eigen::AMDOrdering<int>()(rest, amd_rest);
      Eigen::MetisOrdering<int>()(rest, metis_rest);
    }
    amd_inverse = with_rows_last(amd_rest, first);
    metis_inverse = with_rows_last(metis_rest, first);
  }
  order_ = metis_inverse.inverse();
  llt_.analyzePattern(ordered(A));
  const Eigen::Index metis_nonzeros = llt_.matrixL().nestedExpression().nonZeros();
  order_ = amd_inverse.inverse();
  llt_.analyzePattern(ordered(A));
  if (metis_nonzeros < llt_.matrixL().nestedExpression().nonZeros()) {
    order_ = metis_inverse.inverse();
    llt_.analyzePattern(ordered(A));
  }
  ready_ = false;
  // The factorisation's multiply-adds: sum_j c_j^2 over L's column counts (analyzePattern
  // has laid out L's columns), against the 2 nnz(L) of a solve.
  const Eigen::SparseMatrix<double>& L = lower();
  double factorisation = 0.0;
  for (Eigen::Index j = 0; j < L.cols(); ++j) {
    const double count = static_cast<double>(L.outerIndexPtr()[j + 1] - L.outerIndexPtr()[j]);
    factorisation += count * count;
  }
  factorisation_in_solves_ = factorisation / (2.0 * static_cast<double>(std::max<Eigen::Index>(1, L.nonZeros())));
  outer_.clear();
  inner_.clear();
  if (A.isCompressed()) {
    outer_.assign(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1);
    inner_.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
  }
}

bool FactorisedPreconditioner::same_pattern(const Eigen::SparseMatrix<double>& A) const {
  return A.isCompressed() && !outer_.empty() &&
         static_cast<Eigen::Index>(outer_.size()) == A.outerSize() + 1 &&
         static_cast<Eigen::Index>(inner_.size()) == A.nonZeros() &&
         std::equal(outer_.begin(), outer_.end(), A.outerIndexPtr()) &&
         std::equal(inner_.begin(), inner_.end(), A.innerIndexPtr());
}

void FactorisedPreconditioner::operator()(const Eigen::VectorXd& r, Eigen::VectorXd& z) const {
  const int n = static_cast<int>(r.size());
  const int* order = this->order();
  Eigen::VectorXd y(n);
  for (int i = 0; i < n; ++i) y[order[i]] = r[i];
  supernodes_.solve(y);
  z.resize(n);
  for (int i = 0; i < n; ++i) z[i] = y[order[i]];
}

double FactorisedPreconditioner::bytes() const {
  if (!ready_) return 0.0;
  const double nonzeros = static_cast<double>(llt_.matrixL().nestedExpression().nonZeros());
  return nonzeros * static_cast<double>(sizeof(double) + sizeof(int)) + supernodes_.bytes();
}

}  // namespace sigmafem
