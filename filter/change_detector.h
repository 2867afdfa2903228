// ChangeDetector: notices a sudden change of the system (a ligament cut) from the filter's
// innovations, so that the filter can open up its parameter covariance and follow the
// change fast, while staying quiet (small drift) when nothing changes.
//
// Test: over the last `window` steps, the sum of the normalised innovations squared
// (z^T S^-1 z, each chi-square with m_k degrees of freedom if the model is right) is compared
// with the chi-square quantile of probability 1 - false_alarm for sum m_k degrees of freedom.
// After it fires it stays silent for `hold_off` steps while the filter settles.
#pragma once

#include <deque>

namespace sigmafem {

struct ChangeDetectorOptions {
  bool enabled = true;
  int window = 10;                 // steps summed
  double false_alarm = 1e-9;       // probability that one test fires on a correct model
  int hold_off = 50;               // steps of silence after firing
  double inflation_log_std = 0.7;  // how much the parameter std (log) is widened on firing
  // The catch-up after a change (EstimationStep::catching_up): at most this many steps after
  // firing; 0: none.
  int max_catch_up = 300;
};

class ChangeDetector {
 public:
  explicit ChangeDetector(const ChangeDetectorOptions& options) : options_(options) {}
  // Adds one step's NIS with its degrees of freedom; returns true when the test fires.
  bool update(double normalised_innovation, int degrees_of_freedom);
  // The statistic of the last update and the threshold it was compared with.
  double statistic() const { return statistic_; }
  double threshold() const { return threshold_; }
  // True when the last window is full and its sum is within the threshold: the innovations
  // are back to what the model explains (ends a catch-up).
  bool settled() const {
    return static_cast<int>(nis_.size()) == options_.window && statistic_ <= threshold_;
  }

 private:
  ChangeDetectorOptions options_;
  std::deque<double> nis_;
  std::deque<int> dof_;
  int silent_for_ = 0;
  double statistic_ = 0.0, threshold_ = 0.0;
};

// The chi-square quantile of probability 1 - tail for k degrees of freedom
// (Wilson-Hilferty cube-root normal approximation: within about 1% for k >= 10).
double chi_square_upper_quantile(int k, double tail);

}  // namespace sigmafem
