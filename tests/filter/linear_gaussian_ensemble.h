// LinearGaussianEnsemble: a fake Ensemble whose "simulation" is linear,
//   x_{k+1} = A x_k + B theta + c u_k,   y = H x,
// with u_k the x coordinate of the SO position. On such a model with a known initial state,
// Gaussian parameter prior and Gaussian observation noise, the exact Kalman filter on
// [x; theta] is known, and the ROUKF must reproduce it (docs/ROUKF.md).
#pragma once

#include <Eigen/Core>

#include "filter/ensemble.h"

namespace sigmafem::testing {

class LinearGaussianEnsemble : public Ensemble {
 public:
  LinearGaussianEnsemble(Eigen::MatrixXd A, Eigen::MatrixXd B, Eigen::VectorXd c,
                         Eigen::MatrixXd H, const Eigen::VectorXd& x0, int sigma_count)
      : A_(std::move(A)), B_(std::move(B)), c_(std::move(c)), H_(std::move(H)),
        X_(x0.replicate(1, sigma_count)) {}

  int sigma_count() const override { return static_cast<int>(X_.cols()); }
  int parameter_count() const override { return static_cast<int>(B_.cols()); }
  int observation_count() const override { return static_cast<int>(H_.rows()); }
  void set_parameters(const Eigen::MatrixXd& theta) override { theta_ = theta; }
  StepReport advance(const Eigen::Vector3d& so_position) override {
    X_ = A_ * X_ + B_ * theta_ + c_.replicate(1, X_.cols()) * so_position.x();
    StepReport report;
    report.cg_iterations.assign(X_.cols(), 0);
    report.relative_residual.assign(X_.cols(), 0.0);
    report.converged.assign(X_.cols(), 1u);
    return report;
  }
  void predicted_observations(Eigen::MatrixXd& y) const override { y = H_ * X_; }
  void recenter(const Recentering& r) override {
    const Eigen::VectorXd x_hat = estimate(r.alpha, r.directions, r.correction);
    const Eigen::MatrixXd L = r.alpha * X_ * r.directions.transpose() * r.factor;
    X_ = x_hat.replicate(1, X_.cols()) + L * r.directions;
  }
  // The corrected state estimate mean + L k from the current (predicted) sigma states.
  Eigen::VectorXd estimate(double alpha, const Eigen::MatrixXd& directions,
                           const Eigen::VectorXd& correction) const {
    const Eigen::VectorXd mean = alpha * X_.rowwise().sum();
    return mean + alpha * X_ * directions.transpose() * correction;
  }

 private:
  Eigen::MatrixXd A_, B_;
  Eigen::VectorXd c_;
  Eigen::MatrixXd H_;
  Eigen::MatrixXd X_;       // n x S
  Eigen::MatrixXd theta_;   // p x S
};

}  // namespace sigmafem::testing
