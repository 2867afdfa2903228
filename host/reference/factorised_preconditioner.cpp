#include "host/reference/factorised_preconditioner.h"

#include <algorithm>

namespace sigmafem {

bool FactorisedPreconditioner::factorise(const Eigen::SparseMatrix<double>& A) {
  // The ordering (AMD) and the symbolic analysis depend only on the pattern, and cost 60% of
  // a numeric factorisation on the liver: made again only when the pattern changes (an
  // AssemblyPattern keeps it the same from step to step). The numbers are compute()'s.
  if (!same_pattern(A)) {
    llt_.analyzePattern(A);
    outer_.clear();
    inner_.clear();
    if (A.isCompressed()) {
      outer_.assign(A.outerIndexPtr(), A.outerIndexPtr() + A.outerSize() + 1);
      inner_.assign(A.innerIndexPtr(), A.innerIndexPtr() + A.nonZeros());
    }
  }
  llt_.factorize(A);
  ready_ = llt_.info() == Eigen::Success;
  fresh_ = true;
  if (ready_) ++factorisations_;
  return ready_;
}

bool FactorisedPreconditioner::same_pattern(const Eigen::SparseMatrix<double>& A) const {
  return A.isCompressed() && !outer_.empty() &&
         static_cast<Eigen::Index>(outer_.size()) == A.outerSize() + 1 &&
         static_cast<Eigen::Index>(inner_.size()) == A.nonZeros() &&
         std::equal(outer_.begin(), outer_.end(), A.outerIndexPtr()) &&
         std::equal(inner_.begin(), inner_.end(), A.innerIndexPtr());
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
