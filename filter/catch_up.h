// The catch-up after a detected change (docs/ROUKF.md, "Catch-up after a detected change"):
// the reduced-order filter corrects the state only along the parameters' sensitivities, so
// after a cut the state it carries needs time to meet the organ's new motion even with the
// right parameters. From the first step of the window that found the change (the NIS
// detector's, or the parameter-change test's on a fresh change) until the NIS has settled
// after the detector's hold-off and the innovations' mean is back (RecoveryCheck), or
// max_steps after the finding step, the constants are held (Roukf::hold_constants) and the
// steps are marked (EstimationStep::catching_up): the residual tests and diagnose's
// likelihood comparisons leave them out. A finding during a catch-up continues it (the cap
// counts from its start).
#pragma once

namespace sigmafem {

class CatchUp {
 public:
  CatchUp(int hold_off, int max_steps) : hold_off_(hold_off), max_steps_(max_steps) {}
  // A change found at step `index` (steps made, from 0): begins a catch-up unless one runs.
  // Returns whether one began (the caller marks the finding window's earlier steps).
  bool begin(int index) {
    if (running()) return false;
    start_ = index;
    return true;
  }
  bool running() const { return start_ >= 0; }
  // Step `index` is made; `back`: the NIS has settled and the innovations' mean is back.
  // Returns whether the step belongs to the catch-up (which ends at the first that does not).
  bool update(int index, bool back) {
    if (!running()) return false;
    const int since = index - start_;   // 0: the finding step
    if ((since > hold_off_ && back) || since >= max_steps_) {
      start_ = -1;
      return false;
    }
    return true;
  }

 private:
  int hold_off_, max_steps_;
  int start_ = -1;   // the finding step of the running catch-up; -1: none
};

}  // namespace sigmafem
