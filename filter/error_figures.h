// ErrorFigures: how well an estimation followed the truth (issue 3; the seed paper's
// "average difference"). The run is split into phases at the steps where the truth changes
// (before the cut, after the cut). For each phase, over its last 20% of steps:
//   mean_abs_error    mean over ligaments of |estimate - truth| (N/m), averaged over steps
//   coverage          share of (step, ligament) pairs with the truth inside estimate +- 2 std
// and for a phase that starts with a change:
//   steps_to_follow   filter steps from the change until every estimate stays within 5% of
//                     the new truth (within 5 N/m for a ligament whose truth is under 100 N/m,
//                     i.e. the cut one) for the rest of the phase; -1 if it never does
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace sigmafem {

struct PhaseErrors {
  std::string name;          // "before_cut", "after_cut" (or "phase_N")
  int first_step = 0;        // data row of the phase's first filter step
  int last_step = 0;
  double mean_abs_error = 0.0;
  double coverage = 0.0;
  int steps_to_follow = -1;  // only for phases that start with a change
  std::vector<double> final_error;   // |estimate - truth| per ligament at the last step
};

// `steps` are the data rows of the estimates; `estimate` and `std` are (steps x p); `truth`
// is (steps x p), the truth of the same ligaments at the same rows.
std::vector<PhaseErrors> error_figures(const std::vector<int>& steps, const Eigen::MatrixXd& estimate,
                                       const Eigen::MatrixXd& std, const Eigen::MatrixXd& truth);

}  // namespace sigmafem
