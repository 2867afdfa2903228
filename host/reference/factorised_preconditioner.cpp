#include "host/reference/factorised_preconditioner.h"

namespace sigmafem {

bool FactorisedPreconditioner::factorise(const Eigen::SparseMatrix<double>& A) {
  // compute() orders (AMD) and factorises; the ordering is cheap next to the factorisation,
  // and redoing it keeps the factor right if a pattern ever changes.
  llt_.compute(A);
  ready_ = llt_.info() == Eigen::Success;
  fresh_ = true;
  if (ready_) ++factorisations_;
  return ready_;
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
