#include "host/reference/factorised_preconditioner.h"

#include <algorithm>

namespace sigmafem {

bool FactorisedPreconditioner::factorise(const Eigen::SparseMatrix<double>& A) {
  // The ordering (AMD) and the symbolic analysis depend only on the pattern, and cost 60% of
  // a numeric factorisation on the liver: made again only when the pattern changes (an
  // AssemblyPattern keeps it the same from step to step). The numbers are compute()'s.
  if (!same_pattern(A)) analyse(A);
  llt_.factorize(A);
  ready_ = llt_.info() == Eigen::Success;
  fresh_ = true;
  if (ready_) ++factorisations_;
  return ready_;
}

void FactorisedPreconditioner::analyse(const Eigen::SparseMatrix<double>& A) {
  llt_.analyzePattern(A);
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
  const Eigen::SparseMatrix<double>& L = lower();
  const int n = static_cast<int>(L.cols());
  const int* begin = L.outerIndexPtr();   // column j: entries begin[j] (the diagonal) .. begin[j + 1]
  const int* row = L.innerIndexPtr();
  const double* value = L.valuePtr();
  const int* order = this->order();
  Eigen::VectorXd y(n);
  for (int i = 0; i < n; ++i) y[order[i]] = r[i];
  // L y' = y, column by column: each solved entry is taken out of the rows below it.
  for (int j = 0; j < n; ++j) {
    const double solved = y[j] / value[begin[j]];
    y[j] = solved;
    for (int k = begin[j] + 1; k < begin[j + 1]; ++k) y[row[k]] -= value[k] * solved;
  }
  // L^T x = y', row j of L^T being column j of L, from the last row up.
  for (int j = n - 1; j >= 0; --j) {
    double sum[4] = {0.0, 0.0, 0.0, 0.0};
    int k = begin[j] + 1;
    for (; k + 3 < begin[j + 1]; k += 4)
      for (int lane = 0; lane < 4; ++lane) sum[lane] += value[k + lane] * y[row[k + lane]];
    for (; k < begin[j + 1]; ++k) sum[0] += value[k] * y[row[k]];
    y[j] = (y[j] - ((sum[0] + sum[1]) + (sum[2] + sum[3]))) / value[begin[j]];
  }
  z.resize(n);
  for (int i = 0; i < n; ++i) z[i] = y[order[i]];
}

double FactorisedPreconditioner::bytes() const {
  if (!ready_) return 0.0;
  const double nonzeros = static_cast<double>(llt_.matrixL().nestedExpression().nonZeros());
  return nonzeros * static_cast<double>(sizeof(double) + sizeof(int));
}

void FactorisedPreconditioner::record(int most_iterations) {
  last_ = most_iterations;
  if (fresh_) after_ = ready_ ? most_iterations : -1;
  fresh_ = false;
}

}  // namespace sigmafem
