// ParameterDrift: the extra drift a found parameter change opens, and the follow-up window of a
// fresh change.
#include "filter/parameter_drift.h"

#include <gtest/gtest.h>

#include <cmath>

namespace sigmafem {
namespace {

ParameterChange change_of(Eigen::VectorXd jump, bool follow_up) {
  ParameterChange change;
  change.fired = true;
  change.jump = std::move(jump);
  change.follow_up = follow_up;
  return change;
}

TEST(ParameterDrift, DecaysFromTheLastOpeningOfEachParameter) {
  ParameterChangeTestOptions options;
  ParameterDrift drift(options, 3);
  EXPECT_EQ(drift.variance(0.0).maxCoeff(), 0.0) << "nothing opened, no extra drift";
  const Eigen::Vector3d jump(0.0, 0.4, 0.0);
  drift.record(50.0, jump, change_of(jump, false));
  const double q2 = options.drift_log_std * options.drift_log_std;
  const Eigen::VectorXd at = drift.variance(50.0), later = drift.variance(50.0 + options.drift_decay_steps);
  EXPECT_EQ(at[0], 0.0);
  EXPECT_EQ(at[2], 0.0) << "only the parameters the jump concerns";
  EXPECT_DOUBLE_EQ(at[1], q2);
  EXPECT_NEAR(later[1], q2 * std::exp(-2.0), 1e-15) << "the std decays with drift_decay_steps";
}

TEST(ParameterDrift, AFreshChangeIsFollowedUpTheWayItBeganAndFollowUpsDoNotChain) {
  ParameterChangeTestOptions options;
  ParameterDrift drift(options, 2);
  const double span = std::log(100.0) * options.drift_decay_steps;   // until the drift is down to 1%
  const Eigen::Vector2d fresh(-0.5, 0.0);
  drift.record(100.0, fresh, change_of(fresh, false));
  EXPECT_TRUE(drift.followed_up(100.0 + span - 1.0)[0]);
  EXPECT_FALSE(drift.followed_up(100.0 + span - 1.0)[1]);
  EXPECT_FALSE(drift.followed_up(100.0 + span + 1.0)[0]);
  EXPECT_TRUE(drift.goes_on(change_of(Eigen::Vector2d(-0.2, 0.0), true)));
  EXPECT_FALSE(drift.goes_on(change_of(Eigen::Vector2d(0.2, 0.0), true))) << "a follow-up the other way";
  EXPECT_TRUE(drift.goes_on(change_of(Eigen::Vector2d(0.2, 0.0), false))) << "a fresh change either way";
  // A follow-up's own opening keeps the drift going, not the follow-up window.
  const Eigen::Vector2d more(-0.2, 0.0);
  drift.record(150.0, more, change_of(more, true));
  EXPECT_FALSE(drift.followed_up(100.0 + span + 1.0)[0]);
  EXPECT_DOUBLE_EQ(drift.variance(150.0)[0], options.drift_log_std * options.drift_log_std);
}

}  // namespace
}  // namespace sigmafem
