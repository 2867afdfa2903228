// BackgroundMaking: a preconditioner made again on a host thread while the ensemble steps on
// with the last one, as SOFA's asynchronous preconditioner does, but handed over at a step
// fixed when the making began (`lag` steps later) rather than whenever it is done: the runs
// repeat bit for bit whatever the machine's load. Where a refactorisation took seconds (the
// 38k liver's shared factor on PoCL: the filter step it fell in took 1.5-1.85 s against a
// median of 68 ms, bench/RESULTS.md, stop 62), its work is spread over the steps in between.
// The owner must not touch what `make` works on until hand_over() says so.
#pragma once

#include <functional>
#include <future>
#include <utility>

namespace sigmafem {

class BackgroundMaking {
 public:
  BackgroundMaking() = default;
  BackgroundMaking(const BackgroundMaking&) = delete;
  BackgroundMaking& operator=(const BackgroundMaking&) = delete;
  // Waits for a making still running (its result unused).
  ~BackgroundMaking() {
    if (future_.valid()) future_.wait();
  }

  // Which makings go to the background: those of `least_work` or more (in the owner's unit),
  // handed over `lag` steps after they begin; lag 0: none.
  void set_rule(int lag, double least_work) {
    lag_ = lag;
    least_work_ = least_work;
  }
  bool takes(double work) const { return lag_ > 0 && work >= least_work_; }
  // Whether a making is running or waiting to be handed over.
  bool pending() const { return future_.valid(); }
  // Starts `make` (true where it succeeded) on its own thread, to be handed over at the
  // lag-th hand_over() from now.
  void start(std::function<bool()> make) {
    steps_left_ = lag_ < 1 ? 1 : lag_;
    future_ = std::async(std::launch::async, std::move(make));
  }
  // Once at the start of each step while pending(): whether this is the step to hand the
  // making over; then it has been waited for, `ok` is its result, and pending() is false. An
  // exception thrown by the making is thrown here.
  bool hand_over(bool& ok) {
    if (--steps_left_ > 0) return false;
    ok = future_.get();
    return true;
  }

 private:
  std::future<bool> future_;
  int steps_left_ = 0;
  int lag_ = 0;
  double least_work_ = 0.0;
};

}  // namespace sigmafem
