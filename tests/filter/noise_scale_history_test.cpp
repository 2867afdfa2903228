// NoiseScaleHistory: a change detector is armed only when the adaptive noise stayed off over
// the given steps before its window.
#include "filter/noise_scale_history.h"

#include <gtest/gtest.h>

namespace sigmafem {
namespace {

TEST(NoiseScaleHistory, QuietOnlyWhenNoStepBeforeTheWindowWasScaled) {
  NoiseScaleHistory history(/*window=*/3, /*longest=*/5);
  for (int k = 0; k < 7; ++k) history.record(false);
  EXPECT_TRUE(history.quiet_before_window(3));
  EXPECT_FALSE(history.quiet_before_window(5)) << "8 steps needed, 7 made";
  history.record(true);   // inside the window: does not disarm
  EXPECT_TRUE(history.quiet_before_window(5));
  for (int k = 0; k < 3; ++k) history.record(false);   // the scaled step is now just before the window
  EXPECT_FALSE(history.quiet_before_window(1));
  for (int k = 0; k < 5; ++k) history.record(false);   // and 6 steps before it
  EXPECT_TRUE(history.quiet_before_window(5));
  EXPECT_FALSE(history.quiet_before_window(6)) << "only window + longest steps are kept";
}

}  // namespace
}  // namespace sigmafem
