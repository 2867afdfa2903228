// ChangeDetector: notices a sudden change of the system (a ligament cut) from the filter's
// innovations, so that the filter can open up its parameter covariance and follow the
// change fast, while staying quiet (small drift) when nothing changes.
//
// Test: over the last `window` steps, the sum of the normalised innovations squared
// (z^T S^-1 z, each chi-square with m_k degrees of freedom if the model is right) is compared
// with the chi-square quantile of probability 1 - false_alarm for sum m_k degrees of freedom,
// if the model explained the reference_windows x window steps before them (their sum within
// its chi-square quantile of probability 1 - model_error_false_alarm; several windows, so
// that a model error of 1.4 per degree of freedom is not taken for a consistent model by
// chance and then tested nominally). If it did not, the model has an error
// that persists with nothing changing (measured on the shipped liver with the truth on the
// mesh refined once: NIS levels of 1.3 to 2.2 per degree of freedom; the nominal test fired at
// steps 177 and 228, and the covariance it opened let the right ligament run from 7e3 to 1e9
// N/m in 22 steps). Then the test is for a jump of the level: the variance-ratio test of the
// tested window and the reference, their levels' ratio against the F quantile of probability
// 1 - false_alarm.
// A consistent model's reference fails its test with probability model_error_false_alarm,
// and the F test is then the stricter one: the false-alarm rate stays below false_alarm.
// It tests once the reference is full ((1 + reference_windows) x window steps from the start
// or from its last firing), and after firing stays silent for `hold_off` steps while the filter settles.
#pragma once

#include <deque>

namespace sigmafem {

struct ChangeDetectorOptions {
  bool enabled = true;
  int window = 10;                 // steps summed
  double false_alarm = 1e-9;       // probability that one test fires on a correct model
  int hold_off = 50;               // steps of silence after firing
  // The reference: this many windows before the tested one, and the probability that a
  // consistent model's reference is taken for a model error.
  int reference_windows = 5;
  double model_error_false_alarm = 1e-3;
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
  // The statistic of the last update, and the threshold and reference level of the last test
  // (made once the reference is full and the hold-off is over).
  double statistic() const { return statistic_; }
  double threshold() const { return threshold_; }
  // The reference window's NIS per degree of freedom when it showed a model error, else 1.
  double reference_level() const { return reference_level_; }
  // True when the last test's reference showed no model error: the model explained the data
  // before the tested window (false before the first test).
  bool model_explained_reference() const { return tested_ && reference_level_ == 1.0; }
  // True when the last window is full and its NIS per degree of freedom is within the
  // threshold per degree of freedom of the last firing (before any firing: of the last test):
  // the innovations are back to what the model explained before the change (ends a catch-up,
  // also one that the parameter-change test began).
  bool settled() const {
    return static_cast<int>(nis_.size()) >= options_.window &&
           statistic_ <= settle_threshold_per_dof_ * tested_dof_;
  }

 private:
  ChangeDetectorOptions options_;
  std::deque<double> nis_;   // the last (1 + reference_windows) windows of steps: the reference, then the tested one
  std::deque<int> dof_;
  int silent_for_ = 0;
  double statistic_ = 0.0, threshold_ = 0.0;
  int tested_dof_ = 0;   // the degrees of freedom of the tested window (its last W steps)
  double reference_level_ = 1.0, settle_threshold_per_dof_ = 0.0;
  bool fired_ = false, tested_ = false;
};

}  // namespace sigmafem
