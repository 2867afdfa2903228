// ParameterChangeTest: have the parameters changed? A score test on the part of the innovation
// that a change of the parameters explains (issue 16), the counterpart for P of the adaptive
// observation noise (filter/adaptive_noise.h), which matches R to the part they do not explain.
//
// Why not the NIS (filter/change_detector.h): a cut changes the innovation along the few
// directions HL of the parameters' sensitivities, and the NIS sums its square with the m - p
// directions that only carry noise (33 of 36 rows on the shipped scenarios). A gradual change,
// as the liver's cut is seen through 0.5 mm noise, never lifts a 10-step NIS above its
// threshold (measured: detected on 2 of 5 seeds, 30 steps late), while it shows as a steady
// mean of the projected innovation, which sums up over steps.
//
// Test (the score test of Rao, the generalised likelihood ratio test for a jump of Willsky and
// Jones 1976, "A generalized likelihood ratio approach to the detection and estimation of jumps
// in linear systems"): each step's score s_k = H^T R^-1 z_k (p; H the sensitivities of the
// predicted observations to theta) has, for a consistent filter, mean 0 and covariance
// V_k = H^T R^-1 S_k R^-1 H, independently from step to step (a consistent filter's innovations
// are white). Over the last W steps, G = sum s_k and V = sum V_k, and T = G^T V^+ G is
// chi-square with rank(V) degrees of freedom. For a jump nu of theta that the filter has not
// followed, s_k has mean H^T R^-1 H nu, and nu_hat = V^+ G estimates it. The test runs on
// several windows (a cut is sudden, a drift through noise slow), each at `false_alarm`, and
// after it fires its sums start again.
// Only the parameters marked active take part (not the constants of the setup, not a
// ligament already cut). The jump is estimated with the parameters' prior as its prior,
// nu_hat = (V + D^-1)^-1 G, D the prior variances: V^+ G alone put a jump of +1 to +2.4 log
// units on the right ligament of the liver when the middle one was cut (the two, 3 cm apart,
// are told apart only over many steps; in a 10-step window their difference is mostly noise)
// and the right estimate ran to 11 times its truth.
//
// The follow-up: a jump that the linear model can only see in part (a ligament cut from 180 N/m
// to zero is a jump of -9.8 in log k, and one opening is clamped at the prior std) leaves
// the parameter crawling down in log k, where each step's information shrinks as k^2: measured
// on the liver with the middle ligament at 180 N/m (seeds 21-23), it sat at 30 N/m 50 steps
// after the cut and at 12 N/m 400 steps after it, its +-2 std far from zero, while no window
// reached the threshold of a fresh change again. A parameter that changed recently (the
// caller marks it) is therefore tested alone as well, G_j^2 / V_jj against chi-square(1) at
// the follow-up's false alarm: the change is already known, so the rest of it needs less
// evidence than its start.
#pragma once

#include <Eigen/Core>
#include <deque>
#include <vector>

namespace sigmafem {

struct ParameterChangeTestOptions {
  bool enabled = true;
  std::vector<int> windows = {10, 40, 160};   // steps summed, each tested
  double false_alarm = 1e-6;                  // per window and step, on a consistent filter
  double follow_up_false_alarm = 1e-3;        // per window and step, a recently changed parameter alone
  // A parameter takes part once its std has fallen below this fraction of its prior std
  // (filter/estimation.cpp): before, the filter is still learning the constant, and a jump
  // cannot be told from that. Measured: with an undeclared 0.1 s lag on the shipped liver the
  // test fired at step 57 on the left ligament (its std still 0.86 of its prior), opened it by
  // the prior std five times by step 123, and the declared model's filter diverged at step 137.
  double learned_fraction = 0.5;
  // Acted on only when the adaptive observation noise has not engaged in this many steps
  // before the NIS detector's window (filter/noise_scale_history.h): a model error engages it now
  // and then, and between times shows as jumps (the same lag: firings at steps 153-947 with
  // the noise scaled on 840 steps, the ligaments ending at 0.003 N/m and 1.4e7 N/m).
  int quiet_steps = 100;
  // The response (filter/parameter_drift.h): P opened by nu_hat nu_hat^T at the firing, and the
  // parameters it concerns drift by this much per step (log units), decaying with this
  // time constant (steps) back to the scenario's drift.
  double drift_log_std = 0.035;
  double drift_decay_steps = 100.0;
};

struct ParameterChange {
  bool fired = false;
  int window = 0;              // the window that fired (the most significant)
  double statistic = 0.0;      // its T
  double threshold = 0.0;      // and the chi-square quantile T exceeded
  Eigen::VectorXd jump;        // nu_hat (p, 0 on inactive parameters)
  bool follow_up = false;      // found by the follow-up (one recently changed parameter alone)
};

class ParameterChangeTest {
 public:
  explicit ParameterChangeTest(const ParameterChangeTestOptions& options);
  // One step's score (p) and its covariance (p x p), theta coordinates; `active` (p) marks the
  // parameters tested, `follow_up` (p, or empty: none) those also tested alone at the
  // follow-up's false alarm. Returns what the test found this step.
  ParameterChange update(const Eigen::VectorXd& score, const Eigen::MatrixXd& covariance,
                         const std::vector<bool>& active, const std::vector<bool>& follow_up = {});
  // Forgets the sums (the filter was reset, or its steps are no longer comparable).
  void restart() { steps_.clear(); }

 private:
  struct Step {
    Eigen::VectorXd score;
    Eigen::MatrixXd covariance;
  };
  ParameterChangeTestOptions options_;
  std::deque<Step> steps_;   // the last max(windows) steps, the newest at the back
};

}  // namespace sigmafem
