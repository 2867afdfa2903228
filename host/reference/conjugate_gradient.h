// conjugate_gradient: preconditioned conjugate gradients for a symmetric positive definite
// system given only by its product, written like Eigen's internal::conjugate_gradient (a bare
// function; the caller owns the operator and the preconditioner). Jacobi is the oracle's and
// the device kernels' preconditioner; the CPU back end uses sparse Cholesky factors instead
// (factorised_preconditioner.h). The device kernels follow the same stopping rule, so that
// iteration counts can be compared.
//
// Stopping rule: |b - A x| <= tolerance * |b| (relative residual, 2-norm).
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace sigmafem {

struct CgResult {
  int iterations = 0;              // products done (0 when the start already converged)
  double relative_residual = 0.0;  // |b - A x| / |b| at exit (0 for b = 0)
  bool converged = false;          // false: hit max_iterations (a status, not an exception)
};

// Solves A x = b. `x` is the warm start on entry and the solution on exit.
// `apply(d, y)` sets y = A d; `precondition(r, z)` sets z = M^-1 r for an SPD M close to A.
template <class Apply, class Precondition>
CgResult preconditioned_conjugate_gradient(const Apply& apply, const Precondition& precondition,
                                           const Eigen::VectorXd& b, Eigen::VectorXd& x,
                                           int max_iterations, double tolerance) {
  CgResult result;
  const double b_norm = b.norm();
  // An overflowed load would make the stop test tol * |b| infinite and pass at once with
  // nothing solved: report it as a breakdown (not converged, residual NaN) instead.
  if (!std::isfinite(b_norm)) {
    result.relative_residual = std::nan("");
    return result;
  }
  if (b_norm == 0.0) {  // the exact solution is zero; no iteration can improve on it
    x.setZero(b.size());
    result.converged = true;
    return result;
  }
  const double threshold = tolerance * b_norm;
  Eigen::VectorXd Ad(b.size());
  apply(x, Ad);
  Eigen::VectorXd r = b - Ad;                  // residual of the warm start
  double r_norm = r.norm();
  if (r_norm <= threshold) {                   // already converged: keep the warm start
    result.relative_residual = r_norm / b_norm;
    result.converged = true;
    return result;
  }
  Eigen::VectorXd z(b.size());
  precondition(r, z);                                      // preconditioned residual
  Eigen::VectorXd d = z;                                   // search direction
  double rz = r.dot(z);
  while (result.iterations < max_iterations) {
    apply(d, Ad);                              // the cost: one matrix-free product
    ++result.iterations;
    const double alpha = rz / d.dot(Ad);       // step length minimising the A-norm error
    x += alpha * d;
    r -= alpha * Ad;
    r_norm = r.norm();
    if (r_norm <= threshold) {
      result.converged = true;
      break;
    }
    if (!std::isfinite(r_norm)) break;         // not SPD (or NaN input): report, do not spin
    precondition(r, z);
    const double rz_new = r.dot(z);
    d = z + (rz_new / rz) * d;                 // A-conjugate to the previous directions
    rz = rz_new;
  }
  result.relative_residual = r_norm / b_norm;
  return result;
}

// Jacobi-preconditioned CG: `inverse_diagonal` is 1 / diag(A).
template <class Apply>
CgResult conjugate_gradient(const Apply& apply, const Eigen::VectorXd& inverse_diagonal,
                            const Eigen::VectorXd& b, Eigen::VectorXd& x, int max_iterations,
                            double tolerance) {
  const auto jacobi = [&](const Eigen::VectorXd& r, Eigen::VectorXd& z) {
    z = inverse_diagonal.cwiseProduct(r);
  };
  return preconditioned_conjugate_gradient(apply, jacobi, b, x, max_iterations, tolerance);
}

}  // namespace sigmafem
