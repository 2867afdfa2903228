// LigamentCutRule: when do the data show that a ligament was cut? Then the filter sets its
// stiffness to (next to) zero instead of following it down in log space.
//
// Why: theta = log k loses its sensitivity as k -> 0 (the force k u and its derivative in
// theta both vanish), so after a cut the estimate only creeps down, about as 1/sqrt(t).
// Measured on the shipped liver under 9.81 m/s^2 along y with the true model (gravity
// declared, seeds 1 and 2): the cut middle ligament still held 1-1.5 N/m 600-1000 steps after
// the cut (truth 0.01). Against the sag of the full gravity that is a systematic force: the
// residual kept a rigid translation of 0.008 mm (t 2.5) and, on seed 2, a biased row that
// made the tests call the true model inconsistent; a constant fitted beside the stiffnesses
// (an undeclared gravity) took part of it up. With the ligament set to 0.01 N/m from step
// 1150 the translation's t fell to 1.3-1.4 and the row passed.
//
// Rule: armed by a detected change (a cut is a change: the change detector's firing, or the
// parameter-change test's first), with the estimate just before the change began as the
// reference. Ligament j is cut when its upper bound exp(theta + z std) falls below `fraction`
// of its reference's lower bound exp(theta_ref - z std): with z = 2 on both sides, the data
// show that it lost more than 90% of its stiffness. Each ligament is cut once; a later change
// re-arms the rule for the others. (Until issue 16: z = 3 and 95%. With the small drift of
// issue 16 a cut ligament of the liver creeps down in log k as its sensitivity vanishes and
// sat at 6-8 N/m, log-std 0.2-0.3, for 500-900 steps before that bound was met (0.5 mm noise,
// seeds 1-5); the cut was then followed in 606-924 steps where 400 are asked. With 90% at
// 2 std it was followed in 139-324 steps, and no uncut ligament of the box or the liver was
// taken for cut, seeds 1-5, 0.5 mm and noise-free.)
#pragma once

#include <Eigen/Core>
#include <vector>

namespace sigmafem {

struct LigamentCutOptions {
  bool enabled = true;
  double fraction = 0.1;     // cut below this fraction of the reference
  double z = 2.0;            // both bounds are z standard deviations out (in log k)
  // A cut ligament's stiffness is set to this fraction of its reference estimate: log k has
  // no zero, and at 1e-6 of it (3e-4 N/m for 300 N/m) no sigma point's spring is felt.
  double remaining = 1e-6;
};

class LigamentCutRule {
 public:
  // `ligaments`: the first parameters that are log-stiffnesses the rule may cut.
  LigamentCutRule(const LigamentCutOptions& options, int ligaments);

  // A change was detected; theta and log_std: the estimate before it began.
  void arm(const Eigen::VectorXd& theta, const Eigen::VectorXd& log_std);
  // The ligaments this step's estimate shows cut (each reported once, only while armed).
  std::vector<int> update(const Eigen::VectorXd& theta, const Eigen::VectorXd& log_std);

  // The estimate (N/m) ligament j had before the change that armed the rule (NaN: not armed).
  double stiffness_before(int j) const;
  bool is_cut(int j) const { return cut_[static_cast<std::size_t>(j)]; }
  bool armed() const { return armed_; }
  // The upper bound exp(theta + z std) of ligament j when the rule found it cut (N/m; NaN
  // before): what the data showed of it, reported as its uncertainty from then on.
  double upper_bound(int j) const { return upper_bound_[static_cast<std::size_t>(j)]; }

 private:
  LigamentCutOptions options_;
  bool armed_ = false;
  Eigen::VectorXd reference_theta_;
  Eigen::VectorXd reference_lower_log_;   // theta_ref - z std_ref
  std::vector<bool> cut_;
  std::vector<double> upper_bound_;
};

}  // namespace sigmafem
