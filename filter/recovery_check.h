// RecoveryCheck: is the filter's state back after a change? The change detector's settled()
// looks at the NIS, which a bias of a tenth of the noise barely moves (36 rows at 0.1 std:
// +1%). After a cut under a full-size gravity the reduced-order filter's state keeps such an
// error for a while: measured on the shipped liver with the true model (gravity declared,
// seed 4), the mean innovation in y over 25 steps was -0.27, -0.13, -0.095 mm over the 75 steps
// after the catch-up ended on the NIS (0.029 mm its noise), then within about 1-2 of its noise.
// Those steps made the residual tests call the true model inconsistent (rigid_bias,
// whiteness: 4 of 5 seeds) and pulled an estimated gravity 6 of its std in 50 steps.
//
// Test: per axis, a_k = the mean over the step's observed points of z / sqrt(S_ii); over the
// last `window` steps a one-sample t-test of mean(a_k) = 0 (the spread of a_k estimated from
// the window, so the correlation between points of one step is accounted for), two-sided at
// false_alarm / 3 per axis. recovered() is true when no axis is biased.
#pragma once

#include <Eigen/Core>
#include <array>
#include <deque>

namespace sigmafem {

struct RecoveryCheckOptions {
  int window = 25;             // steps
  double false_alarm = 1e-3;   // probability that a recovered state is called biased
};

class RecoveryCheck {
 public:
  explicit RecoveryCheck(const RecoveryCheckOptions& options);
  // One step's innovations and their std (3m rows, x y z per point; NaN = missing).
  void update(const Eigen::VectorXd& innovation, const Eigen::VectorXd& innovation_std);
  // True when the window is full and no axis's mean standardised innovation is significant.
  bool recovered() const;
  // The largest |t| over the axes in the window (0 before it is full).
  double largest_t() const;

 private:
  RecoveryCheckOptions options_;
  double threshold_;                          // |t| above which an axis is biased
  std::deque<std::array<double, 3>> means_;   // a_k per axis (NaN where the axis was not seen)
};

}  // namespace sigmafem
