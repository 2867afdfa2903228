#include "filter/roukf.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace sigmafem {

Roukf::Roukf(const RoukfOptions& options, Ensemble& ensemble)
    : options_(options),
      ensemble_(ensemble),
      points_(make_sigma_points(options.sigma_points,
                                static_cast<int>(options.initial_theta.size()))),
      adaptive_noise_(options.adaptive_noise) {
  const int p = points_.parameter_count();
  if (ensemble.parameter_count() != p || ensemble.sigma_count() != points_.count())
    throw std::invalid_argument("Roukf: the ensemble has " +
                                std::to_string(ensemble.parameter_count()) + " parameters and " +
                                std::to_string(ensemble.sigma_count()) + " sigma points; the " +
                                to_string(points_.set) + " set needs " + std::to_string(p) +
                                " and " + std::to_string(points_.count()));
  if (!(options.observation_std > 0.0))
    throw std::invalid_argument("Roukf: observation_std must be positive");
  if (options.initial_std.size() != 0 && options.initial_std.size() != p)
    throw std::invalid_argument("Roukf: initial_std has " + std::to_string(options.initial_std.size()) +
                                " values for " + std::to_string(p) + " parameters");
  if (options.drift_std.size() != 0 && options.drift_std.size() != p)
    throw std::invalid_argument("Roukf: drift_std has " + std::to_string(options.drift_std.size()) +
                                " values for " + std::to_string(p) + " parameters");
  prior_std_ = options.initial_std.size() == p ? options.initial_std
                                               : Eigen::VectorXd::Constant(p, options.initial_log_std);
  const Eigen::VectorXd& prior_std = prior_std_;
  if (!(prior_std.array() > 0.0).all())
    throw std::invalid_argument("Roukf: every prior std must be positive");
  drift_variance_ = options.drift_std.size() == p
                        ? Eigen::VectorXd(options.drift_std.array().square())
                        : Eigen::VectorXd::Constant(p, options.parameter_drift_log_std *
                                                           options.parameter_drift_log_std);
  if (!options.constant.empty() && options.constant.size() != static_cast<std::size_t>(p))
    throw std::invalid_argument("Roukf: constant has " + std::to_string(options.constant.size()) +
                                " flags for " + std::to_string(p) + " parameters");
  const auto constants = static_cast<Eigen::Index>(std::count(options.constant.begin(), options.constant.end(), true));
  constant_rows_ = Eigen::MatrixXd::Zero(constants, p);
  for (int j = 0, i = 0; j < static_cast<int>(options.constant.size()); ++j)
    if (options.constant[static_cast<std::size_t>(j)]) constant_rows_(i++, j) = 1.0;
  opens_on_change_ = (1.0 - constant_rows_.colwise().sum().transpose().array()).matrix();
  theta_ = options.initial_theta;
  // L = [0; I_p], U^-1 = diag(sigma^2): the state is known, the parameters are not.
  L_theta_ = Eigen::MatrixXd::Identity(p, p);
  U_inv_ = Eigen::MatrixXd(prior_std.array().square().matrix().asDiagonal());
  correction_ = Eigen::VectorXd::Zero(p);
  pending_covariance_ = Eigen::MatrixXd::Zero(p, p);
}

Eigen::MatrixXd Roukf::theta_covariance() const {
  return L_theta_ * U_inv_ * L_theta_.transpose();
}

void Roukf::inflate(double log_std) { pending_variance_ += log_std * log_std; }

void Roukf::open(const Eigen::MatrixXd& covariance) {
  if (covariance.rows() != theta_.size() || covariance.cols() != theta_.size() || !covariance.allFinite())
    throw std::invalid_argument("Roukf::open: expected a finite " + std::to_string(theta_.size()) + " x " +
                                std::to_string(theta_.size()) + " covariance");
  pending_covariance_ += covariance;
}

std::vector<bool> Roukf::changeable() const {
  std::vector<bool> flags(static_cast<std::size_t>(theta_.size()));
  for (Eigen::Index j = 0; j < theta_.size(); ++j) flags[static_cast<std::size_t>(j)] = opens_on_change_[j] > 0.0;
  return flags;
}

void Roukf::fix(int j, double value) {
  if (j < 0 || j >= theta_.size())
    throw std::invalid_argument("Roukf::fix: no parameter " + std::to_string(j));
  theta_[j] = value;
  drift_variance_[j] = 0.0;
  opens_on_change_[j] = 0.0;
}

void Roukf::add_theta_covariance(const Eigen::MatrixXd& covariance) {
  // P_theta + D = L_theta (U^-1 + L_theta^-1 D L_theta^-T) L_theta^T: only U^-1 changes.
  const Eigen::MatrixXd L_inv = L_theta_.inverse();
  U_inv_ += L_inv * covariance * L_inv.transpose();
  U_inv_ = 0.5 * (U_inv_ + U_inv_.transpose());   // keep it exactly symmetric for chol
}

RoukfStep Roukf::step(const Eigen::Vector3d& so_position, const Eigen::VectorXd& y) {
  const int p = points_.parameter_count(), r = points_.count();
  const Eigen::MatrixXd& I = points_.directions;   // p x r
  const double alpha = points_.alpha;
  if (y.size() != ensemble_.observation_count())
    throw std::invalid_argument("Roukf::step: expected " +
                                std::to_string(ensemble_.observation_count()) +
                                " observation values, got " + std::to_string(y.size()));

  if (drift_variance_.maxCoeff() > 0.0 || pending_variance_ > 0.0 || pending_covariance_.any()) {
    // A fixed parameter is not opened: its rows and columns of the opened covariance go.
    const Eigen::MatrixXd opened = opens_on_change_.asDiagonal() * pending_covariance_ * opens_on_change_.asDiagonal();
    add_theta_covariance(Eigen::MatrixXd((drift_variance_ + pending_variance_ * opens_on_change_).asDiagonal()) + opened);
  }
  pending_variance_ = 0.0;
  pending_covariance_.setZero();

  // Sampling.
  const Eigen::LLT<Eigen::MatrixXd> llt(U_inv_);
  if (llt.info() != Eigen::Success)
    throw std::runtime_error("ROUKF: U^-1 is not positive definite (the filter diverged)");
  const Eigen::MatrixXd C = llt.matrixL();
  L_theta_ = L_theta_ * C;
  Recentering recentering;
  recentering.alpha = alpha;
  recentering.directions = I;
  recentering.correction = correction_;
  recentering.factor = C;
  ensemble_.recenter(recentering);
  const Eigen::MatrixXd theta_i = theta_.replicate(1, r) + L_theta_ * I;   // p x r

  // Prediction.
  RoukfStep result;
  ensemble_.set_parameters(theta_i);
  result.ensemble = ensemble_.advance(so_position);
  Eigen::MatrixXd predicted;
  ensemble_.predicted_observations(predicted);   // 3m x r

  // Innovations on the observed rows.
  std::vector<int> rows;
  for (int k = 0; k < y.size(); ++k)
    if (!std::isnan(y[k]) && ensemble_.predicts_row(k)) rows.push_back(k);
  result.outliers = ensemble_.rejected_points();
  Eigen::MatrixXd Z(static_cast<Eigen::Index>(rows.size()), r);
  for (std::size_t j = 0; j < rows.size(); ++j)
    Z.row(static_cast<Eigen::Index>(j)) = y[rows[j]] - predicted.row(rows[j]).array();
  // Outliers (filter/outlier_gate.h), judged with the nominal S, leave with their rows.
  if (options_.outlier_gate.enabled && !rows.empty()) {
    const std::vector<int> outliers =
        gate_sigma_point_innovations(options_.outlier_gate, rows, Z, alpha, I,
                                     options_.observation_std * options_.observation_std, ensemble_.rows_per_point());
    result.outliers.insert(result.outliers.end(), outliers.begin(), outliers.end());
    if (!outliers.empty()) {
      std::vector<int> kept;
      std::vector<Eigen::Index> kept_rows_of_Z;
      for (std::size_t j = 0; j < rows.size(); ++j)
        if (std::find(outliers.begin(), outliers.end(), rows[j] / ensemble_.rows_per_point()) == outliers.end()) {
          kept.push_back(rows[j]);
          kept_rows_of_Z.push_back(static_cast<Eigen::Index>(j));
        }
      Z = Eigen::MatrixXd(Z(kept_rows_of_Z, Eigen::all));
      rows = kept;
    }
  }
  const int m = static_cast<int>(rows.size());
  result.observed_rows = m;
  result.observed_indices = rows;

  // Prediction of the parameter block: theta does not evolve, so the mean stays theta_hat and
  // L_theta = alpha sum theta_i I_i^T (= L_theta for both sets, computed as the definition).
  theta_ = alpha * theta_i.rowwise().sum();
  L_theta_ = alpha * theta_i * I.transpose();

  result.score = Eigen::VectorXd::Zero(p);
  result.score_covariance = Eigen::MatrixXd::Zero(p, p);
  if (m == 0) {
    // Nothing observed: the prior is the posterior (U = I, the old U^-1 is already in L).
    U_inv_ = Eigen::MatrixXd::Identity(p, p);
    correction_ = Eigen::VectorXd::Zero(p);
    result.innovation_rms = std::numeric_limits<double>::quiet_NaN();
  } else {
    const Eigen::VectorXd z_bar = alpha * Z.rowwise().sum();
    result.innovation = z_bar;
    result.innovation_rms = std::sqrt(z_bar.squaredNorm() / m);
    // HL = alpha sum Z_i I_i^T (m x p): H P^- H^T = HL HL^T for either set.
    const Eigen::MatrixXd HL = alpha * Z * I.transpose();
    const double variance = options_.observation_std * options_.observation_std;
    result.noise_scale = adaptive_noise_.update(unexplained_innovation(HL, z_bar, variance, rows, y.size()));
    correct(Z, 1.0 / (variance * result.noise_scale));
    result.normalised_innovation = normalised_innovation(Z, z_bar, 1.0 / variance,
                                                         result.log_det_innovation_covariance);
    // diag(S) = row norms of HL plus R's diagonal: what standardises each row's innovation
    // for the residual diagnostics (nominal R: the diagnostics judge the model as declared).
    result.innovation_variance = HL.rowwise().squaredNorm().array() + variance;
    // The score in theta: H = -HL L_theta^-1 (HL is built from y - predicted: ROUKF.md), s = H^T z_bar / r, and with A = HL^T HL,
    // H^T R^-1 S R^-1 H = L_theta^-T (A / r + A^2 / r^2) L_theta^-1 (S = HL HL^T + r I).
    const Eigen::PartialPivLU<Eigen::MatrixXd> L_lu(L_theta_.transpose());
    const Eigen::MatrixXd HLt_HL = HL.transpose() * HL;
    result.score = -L_lu.solve(HL.transpose() * z_bar / variance);
    const Eigen::MatrixXd half = L_lu.solve(HLt_HL / variance + HLt_HL * HLt_HL / (variance * variance));   // L^-T (..)
    result.score_covariance = L_lu.solve(half.transpose());   // L^-T (..)^T L^-1, (..) symmetric
    if (hold_constants_ && constant_rows_.rows() > 0) {
      // The smallest change of the correction k (in sigma coordinates) that leaves the
      // constants' theta as they are: remove its component along the rows A = E_c L_theta,
      // k -= A^T (A A^T)^-1 A k. The state follows, as it takes L_x k at the next re-sampling.
      const Eigen::MatrixXd A = constant_rows_ * L_theta_;
      correction_ -= A.transpose() * (A * A.transpose()).ldlt().solve(A * correction_);
    }
    theta_ += L_theta_ * correction_;
  }
  result.theta = theta_;
  result.theta_covariance = theta_covariance();
  if (!theta_.allFinite() || !result.theta_covariance.allFinite())
    throw std::runtime_error("ROUKF: the estimate became non-finite");
  return result;
}

void Roukf::correct(const Eigen::MatrixXd& Z, double r_inv) {
  const int p = points_.parameter_count(), r = points_.count();
  const Eigen::MatrixXd& I = points_.directions;   // p x r (I^T is the r x p of ROUKF.md)
  const double alpha = points_.alpha;
  const Eigen::VectorXd z_bar = alpha * Z.rowwise().sum();

  Eigen::MatrixXd HL_t;   // p x m: HL^T
  Eigen::MatrixXd U;
  if (points_.set == SigmaPointSet::simplex) {
    const Eigen::MatrixXd HL = alpha * Z * I.transpose();   // m x p
    HL_t = HL.transpose();
    U = Eigen::MatrixXd::Identity(p, p) + r_inv * HL_t * HL;
  } else {
    // Star: centred innovations and the generalised correction (docs/ROUKF.md, step 4).
    const Eigen::MatrixXd Zc = Z.colwise() - z_bar;                       // m x r
    const Eigen::MatrixXd D_m = r_inv * Zc.transpose() * Zc;              // r x r
    const Eigen::MatrixXd Ir = Eigen::MatrixXd::Identity(r, r);
    const Eigen::MatrixXd D_v = alpha * alpha * I.transpose() * I;        // r x r
    const Eigen::MatrixXd A = Ir + D_m * (alpha * Ir - D_v);
    const Eigen::PartialPivLU<Eigen::MatrixXd> A_lu(A);
    U = Eigen::MatrixXd::Identity(p, p) +
        alpha * alpha * I * A_lu.solve(D_m * I.transpose());
    const Eigen::MatrixXd G = alpha * (Ir + alpha * D_m).partialPivLu().solve(
                                          Ir + D_v * A_lu.solve(D_m)) * I.transpose();  // r x p
    HL_t = G.transpose() * Zc.transpose();                                // p x m
  }
  U = 0.5 * (U + U.transpose());
  const Eigen::LLT<Eigen::MatrixXd> U_llt(U);
  U_inv_ = U_llt.solve(Eigen::MatrixXd::Identity(p, p));
  const Eigen::VectorXd HLt_Rinv_z = r_inv * HL_t * z_bar;
  correction_ = -U_inv_ * HLt_Rinv_z;
}

double Roukf::normalised_innovation(const Eigen::MatrixXd& Z, const Eigen::VectorXd& z_bar,
                                    double r_inv, double& log_det) const {
  // S = H P^- H^T + R with H P^- H^T = HL HL^T, HL = alpha sum Z_i I_i^T (for either set);
  // Woodbury: S^-1 = R^-1 - R^-1 HL (I + HL^T R^-1 HL)^-1 HL^T R^-1.
  const int p = points_.parameter_count();
  const Eigen::MatrixXd HL = points_.alpha * Z * points_.directions.transpose();
  const Eigen::MatrixXd U = Eigen::MatrixXd::Identity(p, p) + r_inv * HL.transpose() * HL;
  const Eigen::VectorXd w = r_inv * HL.transpose() * z_bar;
  const Eigen::LDLT<Eigen::MatrixXd> U_ldlt(U);
  // det S = det(R) det(I_p + HL^T R^-1 HL), R = r I_m.
  log_det = -static_cast<double>(Z.rows()) * std::log(r_inv) +
            U_ldlt.vectorD().array().log().sum();
  return r_inv * z_bar.squaredNorm() - w.dot(U_ldlt.solve(w));
}

}  // namespace sigmafem
