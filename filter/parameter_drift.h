// The response to a parameter change the ParameterChangeTest found (filter/estimation.cpp):
// P is opened along the jump at the firing, and every parameter the jump concerns drifts by
// an extra drift_log_std per step (log units) that decays with drift_decay_steps, so the
// filter keeps following a change the data show slowly (docs/ROUKF.md, "Adaptive parameter
// covariance"). A parameter opened by a fresh change (not a follow-up) is followed up for a
// while: until its extra drift would be below a hundredth of its start (the follow-up test,
// one recently changed parameter alone). A follow-up's own firing keeps the drift going but
// does not extend the follow-up, so false follow-ups cannot chain, and it must go the way
// its change began.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "filter/parameter_change_test.h"

namespace sigmafem {

class ParameterDrift {
 public:
  ParameterDrift(const ParameterChangeTestOptions& options, Eigen::Index parameters);
  // Which parameters are followed up at step k.
  std::vector<bool> followed_up(double k) const;
  // A follow-up the other way from its fresh change's jump is not one (false for `change`).
  bool goes_on(const ParameterChange& change) const;
  // Records the jump (clamped, log units) opened at step k by `change`.
  void record(double k, const Eigen::VectorXd& jump, const ParameterChange& change);
  // The extra drift's variance per parameter at step k (0 where none was opened).
  Eigen::VectorXd variance(double k) const;

 private:
  ParameterChangeTestOptions options_;
  std::vector<double> changed_at_;        // the step of each parameter's last opening
  std::vector<double> fresh_change_at_;   // and of its last opening by a fresh change
  std::vector<double> fresh_jump_;        // that fresh change's jump, log units
};

}  // namespace sigmafem
