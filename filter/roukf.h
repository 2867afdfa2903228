// Roukf: the reduced-order unscented Kalman filter for parameters (docs/ROUKF.md; Moireau and
// Chapelle 2011), as sigmafem uses it: theta = log of the estimated stiffnesses, covariance
// in factored form P = L U^-1 L^T, only p x p matrices on the host (the state block of L
// lives in the Ensemble), simplex or star sigma points, random-walk parameter drift.
//
// One step(so, y):
//   drift      U^-1 += q^2 (L_theta^T L_theta)^-1, i.e. P_theta + q^2 I with the state block
//              following along the regression of the state on theta
//   sampling   C = chol(U^-1), L <- L C; ensemble re-samples its states (Recentering);
//              theta_i = theta_hat + L_theta I_i
//   prediction every sigma point advances one step (ensemble)
//   innovation Z_i = y - H(x_i^-), rows with missing data (NaN) dropped, and the rows of
//              points the outlier gate rejects (filter/outlier_gate.h)
//   correction simplex: HL = alpha sum Z_i I_i^T, U = I + HL^T R^-1 HL,
//              k = -U^-1 HL^T R^-1 z_bar; theta_hat += L_theta k (the ensemble applies
//              L_x k at the next re-sampling); star: the generalised correction of ROUKF.md.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "filter/adaptive_noise.h"
#include "filter/ensemble.h"
#include "filter/outlier_gate.h"
#include "filter/sigma_points.h"

namespace sigmafem {

struct RoukfOptions {
  SigmaPointSet sigma_points = SigmaPointSet::simplex;
  Eigen::VectorXd initial_theta;        // p: prior mean of theta (log of the median stiffness)
  double initial_log_std = 1.0;         // prior standard deviation of each theta
  double parameter_drift_log_std = 0.0; // q: random-walk std of theta per step
  // Per-parameter overrides (size p, or empty: every parameter takes the scalar above). The
  // residual analysis appends effect parameters (host/model/effects.h) in coordinates scaled
  // by their own prior std, which need prior std 1 and no drift (an effect is a constant),
  // beside log-stiffnesses that keep the scenario's prior and drift.
  Eigen::VectorXd initial_std;          // p: prior std of each theta
  Eigen::VectorXd drift_std;            // p: random-walk std of each theta per step
  // The parameters that are constants of the setup (size p, or empty: none): the effect
  // parameters beside the stiffnesses. A detected change (a cut) changes stiffnesses, not
  // gravity or a camera offset, so inflate() leaves these alone, and while hold_constants()
  // is set the corrections leave their estimates where they are.
  std::vector<bool> constant;
  double observation_std = 1e-3;        // sqrt of R's diagonal
  // The correction's R is lambda R when the innovations hold more than the parameters can
  // explain (filter/adaptive_noise.h): the filter stays stable under model error.
  AdaptiveNoiseOptions adaptive_noise;
  // Observed points whose innovation is far outside its predicted band leave the step's
  // correction (filter/outlier_gate.h; off by default).
  OutlierGateOptions outlier_gate;
};

struct RoukfStep {
  Eigen::VectorXd theta;                // corrected theta_hat
  Eigen::MatrixXd theta_covariance;     // L_theta U^-1 L_theta^T
  Eigen::VectorXd innovation;           // z_bar on the observed rows (observed - predicted mean)
  Eigen::VectorXd innovation_variance;  // diag(S) on the observed rows, S = H P^- H^T + R
  std::vector<int> observed_indices;    // the rows of y that `innovation` holds, increasing
  int observed_rows = 0;                // rows of y that were not missing, nor an outlier's
  std::vector<int> outliers;            // points (row / Ensemble::rows_per_point) the gate left out
  double innovation_rms = 0.0;          // sqrt(mean z_bar^2) over the observed rows (NaN if none)
  double normalised_innovation = 0.0;   // z_bar^T S^-1 z_bar, S = H P^- H^T + R (chi^2, m dof)
  // log det S: with the NIS, the step's Gaussian log-likelihood of the innovation
  // -0.5 (NIS + log det S + m log 2 pi), the prediction-error decomposition the residual
  // analysis compares models by. det S = det R det(I + HL^T R^-1 HL) (Sylvester).
  double log_det_innovation_covariance = 0.0;
  // The adaptive noise scale lambda this step's correction used (1: nominal R; the fields
  // above stay nominal).
  double noise_scale = 1.0;
  // The score of theta, s = H^T R^-1 z_bar (p; H = -HL L_theta^-1, the sensitivities of the
  // predicted observations to theta), and its covariance for a consistent filter,
  // H^T R^-1 S R^-1 H (p x p), nominal R: what the parameter-change test sums
  // (filter/parameter_change_test.h). Zero when nothing was observed.
  Eigen::VectorXd score;
  Eigen::MatrixXd score_covariance;
  StepReport ensemble;
};

class Roukf {
 public:
  // The ensemble must have sigma_count() equal to the size of the chosen sigma-point set.
  Roukf(const RoukfOptions& options, Ensemble& ensemble);

  // One filter step with the SO at `so_position` and the measurement `y` (3m, NaN = missing).
  RoukfStep step(const Eigen::Vector3d& so_position, const Eigen::VectorXd& y);

  // Widens the uncertainty of every parameter but the constants by `log_std` (added in
  // quadrature, like drift) before the next sampling: the change detector's response to a
  // sudden change.
  void inflate(double log_std);
  // Adds `covariance` (p x p, symmetric positive semi-definite) to P_theta before the next
  // sampling: the parameter-change test's response, the estimated jump's nu nu^T.
  void open(const Eigen::MatrixXd& covariance);
  // The parameters a change may concern (not the constants, not a fixed one).
  std::vector<bool> changeable() const;
  // While `hold` is set, each correction is projected so that the constants' estimates do not
  // move: the stiffnesses and the state take the innovation. After a change the innovations
  // measure how the state recovers, which no constant explains; let through, they pull a
  // constant away and its narrow std holds it there (measured on the liver under an undeclared
  // oblique gravity: g off by 2-4% with the constants not inflated, the residual biased).
  void hold_constants(bool hold) { hold_constants_ = hold; }
  // Sets parameter j to `value` and stops its drift and its widening on a change (a cut
  // ligament, filter/ligament_cut.h). Corrections may still move it along its covariance with
  // the others, but a log-stiffness with no sensitivity left stays near where it was set.
  void fix(int j, double value);
  // Holds the adaptive noise at lambda = 1 for `steps` steps (AdaptiveNoise::hold).
  void hold_adaptive_noise(int steps) { adaptive_noise_.hold(steps); }

  const SigmaPoints& sigma_points() const { return points_; }
  const Eigen::VectorXd& theta() const { return theta_; }
  // The prior std of each theta (RoukfOptions::initial_std, or initial_log_std for all).
  const Eigen::VectorXd& prior_std() const { return prior_std_; }
  Eigen::MatrixXd theta_covariance() const;
  // The ROUKF factors, for tests against an exact Kalman filter.
  const Eigen::MatrixXd& theta_factor() const { return L_theta_; }
  const Eigen::MatrixXd& U_inverse() const { return U_inv_; }
  const Eigen::VectorXd& last_correction() const { return correction_; }

 private:
  // P_theta += covariance (p x p).
  void add_theta_covariance(const Eigen::MatrixXd& covariance);
  // Kalman correction from the innovations Z (m x r) of the observed rows with R = I / r_inv:
  // sets U_inv_ and correction_.
  void correct(const Eigen::MatrixXd& Z, double r_inv);
  // z^T S^-1 z, and log det S in `log_det`.
  double normalised_innovation(const Eigen::MatrixXd& Z, const Eigen::VectorXd& z_bar,
                               double r_inv, double& log_det) const;

  RoukfOptions options_;
  Ensemble& ensemble_;
  SigmaPoints points_;
  Eigen::VectorXd prior_std_;           // p
  Eigen::VectorXd theta_;               // theta_hat
  Eigen::MatrixXd L_theta_;             // p x p
  Eigen::MatrixXd U_inv_;               // p x p
  Eigen::VectorXd correction_;          // k of the last correction, applied at re-sampling
  double pending_variance_ = 0.0;       // inflation to add before the next sampling
  Eigen::MatrixXd pending_covariance_;  // p x p: opened by a parameter change, added then too
  Eigen::VectorXd opens_on_change_;     // p: 1 where inflate() widens the parameter, else 0
  Eigen::MatrixXd constant_rows_;       // the rows of the identity that pick the constants
  bool hold_constants_ = false;
  Eigen::VectorXd drift_variance_;      // p: q_j^2
  AdaptiveNoise adaptive_noise_;
};

}  // namespace sigmafem
