// RefreshRule: when to make again a preconditioner that is made of one step's matrix and kept
// over later steps (SOFA's asynchronous preconditioner's question; the shared factor,
// host/reference/factorised_preconditioner.h, and the multigrid hierarchy,
// host/reference/nested_multigrid.h). It is due at the start, after a failure, and when the CG
// iterations the steps took beyond the first step's after the last making, counted in the
// work of one application, add up to the work of making it: rent until the rent paid would
// have bought a new one (never more than twice the best cost, whatever comes). The work is
// counted in arithmetic, not measured time, so a run's results do not depend on the machine's
// load.
#pragma once

#include <algorithm>

namespace sigmafem {

class RefreshRule {
 public:
  // After a making: `ok` whether it succeeded, `cost` its work in applications (or the fixed
  // cost, where one is set).
  void made(bool ok, double cost) {
    fresh_ = true;
    ok_ = ok;
    cost_ = fixed_cost_ > 0.0 ? fixed_cost_ : cost;
  }
  // Every making counted as `cost` applications, whatever its work (> 0; tests make it small to
  // make the preconditioner again within a few steps: DeviceOptions::multigrid_making_cycles).
  void fix_cost(double cost) { fixed_cost_ = cost; }
  // Whether to make it before the next step; not between a making and the record() of its
  // first step.
  bool due() const { return !fresh_ && (after_ < 0 || excess_ >= cost_); }
  // The most CG iterations of a step just done (over the systems that share it).
  void record(int most_iterations) {
    if (fresh_) {
      after_ = ok_ ? most_iterations : -1;
      excess_ = 0.0;
    } else if (after_ >= 0) {
      excess_ += std::max(0, most_iterations - after_);
    }
    fresh_ = false;
  }

 private:
  bool fresh_ = false;   // made since the last record()
  bool ok_ = false;
  int after_ = -1;       // iterations of the first step after the making (-1: none yet)
  double excess_ = 0.0;  // beyond after_, summed over the steps since
  double cost_ = 0.0;
  double fixed_cost_ = 0.0;   // 0: each making's own
};

}  // namespace sigmafem
