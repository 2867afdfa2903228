// AdaptiveNoise: keeps the filter stable when the model cannot explain the data (issue 13,
// item 1). A model that lacks an effect (an undeclared gravity, a camera offset, a coarser
// mesh than the organ's) leaves innovations far outside the band S = H P H^T + R predicts;
// a Kalman correction with the nominal R then treats all of it as information about the
// parameters and drives them to their limits in a few dozen steps (measured on the liver with
// an undeclared 9.81 m/s^2: every stiffness out of 1e-6..1e9 N/m (the bound then) by step 42).
//
// The response is innovation-based adaptive estimation of R (Mehra 1972; Mohamed and Schwarz
// 1999, "Adaptive Kalman filtering for INS/GPS"): the correction uses lambda R with lambda
// matched to the innovations over a short window. The part of the innovation that a change of
// the parameters could explain is left out of the match, so that a cut (which the parameters
// explain, and which the change detector answers by opening P) does not inflate R:
//   e = (I - Pi) z,  Pi the orthogonal projection on the columns of HL (the sensitivities of
//   the predicted observations to the parameters, m x p, rank q),
// and under the filter's own model z ~ N(0, HL HL^T + sigma^2 I), so |e|^2 / sigma^2 is exactly
// chi-square with m - q degrees of freedom, whatever P is. Over the last `window` steps:
//   T = sum |e_k|^2 / sigma^2, d = sum (m_k - q_k);
//   lambda = T / d when T exceeds the chi-square(d) quantile of probability 1 - false_alarm,
//   else 1 (a consistent model's filter is left exactly as it is, but with that probability).
// The window includes the current step (its innovation is known before its correction).
// A model error is not white: it persists from step to step (an undeclared gravity pulls at
// every step), so N steps of it carry the information of far fewer than N independent ones,
// and a filter that takes them as white noise walks the parameters steadily to the wrong
// model's least-squares optimum, often a limit (measured: lambda alone held the liver above
// 1e-6 N/m for 661 steps instead of 42). So when lambda > 1 it is multiplied by the
// effective-sample-size factor of an AR(1) error, (1 + rho) / (1 - rho) (e.g. Bayley and
// Hammersley 1946; von Storch and Zwiers, "Statistical Analysis in Climate Research", 6.6), rho
// the mean lag-1 correlation of the unexplained parts e_k . e_k-1 / (|e_k| |e_k-1|) over the
// window, clamped to [0, max_correlation]: the filter then learns from a persistent model error
// at most what one step of it holds.
// What lambda does not change: the innovations, S and the NIS that the residual diagnostics
// and the likelihood read stay nominal (sigma^2), so a model that needed lambda > 1 is still
// called inconsistent; only the gain is tempered.
// With the change detector it is one mechanism (filter/noise_scale_history.h): a jump of the NIS
// while the model explained the data (lambda = 1 on the step before) is a change of the
// parameters: the detector opens P and lambda is held at 1 through its hold-off, so that the
// filter follows (measured on the liver under full gravity: a cut makes the organ swing, a
// state error the one-step sensitivities do not span, and lambda engaged first and stalled the
// following). Innovations beyond the band while lambda > 1 are model error: the detector is
// not armed, and P is not opened again and again by a steady error.
#pragma once

#include <Eigen/Core>
#include <deque>
#include <vector>

namespace sigmafem {

struct AdaptiveNoiseOptions {
  bool enabled = true;
  int window = 5;                  // steps of the match (the current one included)
  double false_alarm = 1e-4;       // P(lambda > 1 at a step | consistent model)
  double max_scale = 1e8;          // lambda's ceiling (a noise std 1e4 times the nominal)
  double max_correlation = 0.999;  // rho's ceiling: a factor of at most 1999
};

// The unexplained part of one step's innovation: e = (I - Pi) z on every data row (NaN where the
// row was not observed), |e|^2 / sigma^2 and its degrees of freedom m - rank(HL) (0 when HL
// spans every observed row). `rows` are the data rows of z and HL (of `row_count`).
struct UnexplainedInnovation {
  Eigen::VectorXd residual;
  double chi_square = 0.0;
  int degrees_of_freedom = 0;
};
UnexplainedInnovation unexplained_innovation(const Eigen::MatrixXd& HL, const Eigen::VectorXd& z,
                                             double observation_variance, const std::vector<int>& rows,
                                             Eigen::Index row_count);

class AdaptiveNoise {
 public:
  explicit AdaptiveNoise(const AdaptiveNoiseOptions& options) : options_(options) {}
  // Adds one step and returns lambda for its correction (>= 1).
  double update(const UnexplainedInnovation& step);
  // Holds lambda at 1 for the next `steps` updates and forgets the window: after a detected
  // change (a cut) the innovations are large while the parameters catch up, and they are
  // the parameters' to explain (the change detector opened P for it), not model error.
  void hold(int steps);
  double scale() const { return scale_; }
  // The window's T / d (1 expected for a consistent model), the threshold T was held to,
  // divided by d, and rho.
  double ratio() const { return ratio_; }
  double threshold_ratio() const { return threshold_ratio_; }
  double correlation() const { return correlation_; }

 private:
  AdaptiveNoiseOptions options_;
  std::deque<UnexplainedInnovation> window_;
  std::deque<double> correlations_;   // lag-1 correlations of the residuals in the window
  double scale_ = 1.0, ratio_ = 1.0, threshold_ratio_ = 1.0, correlation_ = 0.0;
  int held_for_ = 0;
};

}  // namespace sigmafem
