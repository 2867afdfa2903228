#include "filter/adaptive_noise.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <limits>

#include "filter/statistical_distributions.h"

namespace sigmafem {

UnexplainedInnovation unexplained_innovation(const Eigen::MatrixXd& HL, const Eigen::VectorXd& z,
                                             double observation_variance, const std::vector<int>& rows,
                                             Eigen::Index row_count) {
  UnexplainedInnovation u;
  u.residual = Eigen::VectorXd::Constant(row_count, std::numeric_limits<double>::quiet_NaN());
  const Eigen::Index m = z.size();
  if (m == 0) return u;
  // Rank-revealing QR: sigma points that do not move the observations (an unobservable
  // parameter) give a zero column, which spans nothing.
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(HL);
  qr.setThreshold(1e-10);
  const Eigen::Index rank = HL.cols() > 0 ? qr.rank() : 0;
  u.degrees_of_freedom = static_cast<int>(m - rank);
  if (u.degrees_of_freedom <= 0) return u;
  const Eigen::VectorXd residual = rank > 0 ? Eigen::VectorXd(z - HL * qr.solve(z)) : z;
  u.chi_square = residual.squaredNorm() / observation_variance;
  for (Eigen::Index j = 0; j < m; ++j) u.residual[rows[static_cast<std::size_t>(j)]] = residual[j];
  return u;
}

namespace {

// e_a . e_b / (|e_a| |e_b|) over the rows both observed (NaN when they share none).
double residual_correlation(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  double ab = 0.0, aa = 0.0, bb = 0.0;
  for (Eigen::Index i = 0; i < a.size() && i < b.size(); ++i)
    if (std::isfinite(a[i]) && std::isfinite(b[i])) ab += a[i] * b[i], aa += a[i] * a[i], bb += b[i] * b[i];
  return aa > 0.0 && bb > 0.0 ? ab / std::sqrt(aa * bb) : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

void AdaptiveNoise::hold(int steps) {
  held_for_ = steps;
  window_.clear();
  correlations_.clear();
}

double AdaptiveNoise::update(const UnexplainedInnovation& step) {
  scale_ = 1.0;
  if (!options_.enabled) return scale_;
  if (held_for_ > 0) {
    --held_for_;
    return scale_;
  }
  if (step.degrees_of_freedom > 0 && std::isfinite(step.chi_square)) {
    if (!window_.empty()) correlations_.push_back(residual_correlation(window_.back().residual, step.residual));
    window_.push_back(step);
  }
  while (static_cast<int>(window_.size()) > options_.window) window_.pop_front();
  while (static_cast<int>(correlations_.size()) > options_.window - 1) correlations_.pop_front();
  double total = 0.0;
  int dof = 0;
  for (const UnexplainedInnovation& u : window_) total += u.chi_square, dof += u.degrees_of_freedom;
  if (dof == 0) return scale_;
  ratio_ = total / dof;
  threshold_ratio_ = chi_square_tail_quantile(options_.false_alarm, dof) / dof;
  double sum = 0.0;
  int count = 0;
  for (double r : correlations_)
    if (std::isfinite(r)) sum += r, ++count;
  correlation_ = count > 0 ? std::clamp(sum / count, 0.0, options_.max_correlation) : 0.0;
  if (ratio_ > threshold_ratio_)
    scale_ = std::min(ratio_ * (1.0 + correlation_) / (1.0 - correlation_), options_.max_scale);
  return scale_;
}

}  // namespace sigmafem
