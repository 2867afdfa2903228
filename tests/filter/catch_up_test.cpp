// CatchUp: when a catch-up after a detected change begins, how long it lasts, and that a second
// finding continues it instead of restarting the cap.
#include "filter/catch_up.h"

#include <gtest/gtest.h>

namespace sigmafem {
namespace {

TEST(CatchUp, LastsThroughTheHoldOffAndEndsWhenTheStateIsBack) {
  CatchUp catch_up(/*hold_off=*/5, /*max_steps=*/100);
  EXPECT_FALSE(catch_up.update(0, true)) << "no catch-up before a finding";
  EXPECT_TRUE(catch_up.begin(10));
  for (int k = 10; k <= 15; ++k) EXPECT_TRUE(catch_up.update(k, true)) << "within the hold-off: step " << k;
  EXPECT_TRUE(catch_up.update(16, false)) << "after it, while the state is not back";
  EXPECT_FALSE(catch_up.update(17, true)) << "the first step that is back ends it";
  EXPECT_FALSE(catch_up.running());
  EXPECT_FALSE(catch_up.update(18, false));
}

TEST(CatchUp, AFindingDuringACatchUpContinuesItAndTheCapCountsFromItsStart) {
  CatchUp catch_up(5, 20);
  ASSERT_TRUE(catch_up.begin(0));
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(catch_up.update(k, false));
  EXPECT_FALSE(catch_up.begin(10)) << "one catch-up runs";
  for (int k = 10; k < 20; ++k) EXPECT_TRUE(catch_up.update(k, false)) << "step " << k;
  EXPECT_FALSE(catch_up.update(20, false)) << "max_steps after the first finding, even if not back";
  EXPECT_TRUE(catch_up.begin(30)) << "a later change begins a new one";
}

}  // namespace
}  // namespace sigmafem
