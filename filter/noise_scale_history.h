// Whether the adaptive observation noise (filter/adaptive_noise.h) engaged in the steps
// before a change detector's window. One mechanism with the adaptive noise: a jump of the
// NIS is a change of the parameters only if the model explained the data before it, i.e.
// lambda stayed 1 over some steps before the window that found the jump (the adaptive noise,
// on a shorter window, may engage inside it). The NIS detector asks for W quiet steps before
// its window of W; the parameter-change test for a longer quiet history (quiet_steps): a
// model error engages the adaptive noise now and then, and between times shows as jumps. In
// the first steps there is no such history and neither is armed.
#pragma once

#include <algorithm>
#include <cstddef>
#include <deque>

namespace sigmafem {

class NoiseScaleHistory {
 public:
  // Keeps the last `longest` + `window` steps.
  NoiseScaleHistory(std::size_t window, std::size_t longest) : window_(window), kept_(longest + window) {}
  // The step just made: did its correction scale the noise (lambda > 1)?
  void record(bool scaled) {
    scaled_.push_back(scaled);
    if (scaled_.size() > kept_) scaled_.pop_front();
  }
  // No scaled step among the `steps` before the last `window` steps (false until there are that many).
  bool quiet_before_window(std::size_t steps) const {
    return scaled_.size() >= steps + window_ &&
           std::none_of(scaled_.end() - static_cast<std::ptrdiff_t>(steps + window_),
                        scaled_.end() - static_cast<std::ptrdiff_t>(window_), [](bool b) { return b; });
  }

 private:
  std::size_t window_, kept_;
  std::deque<bool> scaled_;   // the last kept_ steps, oldest first
};

}  // namespace sigmafem
