// ParameterChangeTest on synthetic scores: each step's score is N(J nu, V) for a fixed
// covariance V (three ligaments whose sensitivities overlap, as the liver's do) and J = V (a
// filter with a small P: the score's covariance is the Fisher information).
#include "filter/parameter_change_test.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <random>
#include <vector>

namespace sigmafem {
namespace {

// Per-step information of three parameters; the second and third nearly collinear.
Eigen::MatrixXd information() {
  Eigen::MatrixXd V(3, 3);
  V << 4.0, 1.0, 1.0,
       1.0, 2.0, 1.8,
       1.0, 1.8, 2.0;
  return V;
}

struct Firing {
  int step;
  ParameterChange change;
};

// Steps 0..steps-1, the parameters jumped by `jump` from step `at` on; the firings.
std::vector<Firing> feed(ParameterChangeTest& test, int steps, int at, const Eigen::VectorXd& jump,
                         unsigned seed, const std::vector<bool>& active = {true, true, true},
                         const std::vector<bool>& follow_up = {}) {
  const Eigen::MatrixXd V = information();
  const Eigen::MatrixXd root = V.llt().matrixL();
  std::mt19937 random(seed);
  std::normal_distribution<double> normal;
  std::vector<Firing> firings;
  for (int k = 0; k < steps; ++k) {
    Eigen::VectorXd noise(3);
    for (int i = 0; i < 3; ++i) noise[i] = normal(random);
    const Eigen::VectorXd score = (k >= at ? Eigen::VectorXd(V * jump) : Eigen::VectorXd::Zero(3)) + root * noise;
    const ParameterChange change = test.update(score, V, active, follow_up);
    if (change.fired) firings.push_back({k, change});
  }
  return firings;
}

TEST(ParameterChangeTest, SilentWhileNothingChanges) {
  // 3 windows x 20000 steps at 1e-6: 0.06 false alarms expected.
  ParameterChangeTest test{ParameterChangeTestOptions{}};
  EXPECT_TRUE(feed(test, 20000, 20000, Eigen::VectorXd::Zero(3), 1).empty());
}

TEST(ParameterChangeTest, FindsASuddenJumpFastAndNamesTheParameterThatJumped) {
  // The third parameter drops by two log units at step 300 (a cut seen through its first
  // steps; 10 steps of it give T about 3 + 10 * 4 * 2 = 83, the threshold is 30.7): found
  // within the short window, and only that parameter is opened, though its sensitivity
  // overlaps the second's (the least-squares jump over 10 steps spreads onto both).
  ParameterChangeTest test{ParameterChangeTestOptions{}};
  const std::vector<Firing> firings = feed(test, 400, 300, Eigen::Vector3d(0.0, 0.0, -2.0), 2);
  ASSERT_FALSE(firings.empty());
  EXPECT_GE(firings.front().step, 300) << "fired before the jump";
  EXPECT_LT(firings.front().step, 300 + 10);
  const Eigen::VectorXd& jump = firings.front().change.jump;
  EXPECT_EQ(jump[0], 0.0);
  EXPECT_EQ(jump[1], 0.0);
  EXPECT_LT(jump[2], -1.0);
  EXPECT_GT(jump[2], -3.5);
}

TEST(ParameterChangeTest, FindsASlowChangeInItsLongerWindows) {
  // A jump of 0.3 log units on the first parameter: a window of w steps has T about
  // 3 + w * 0.09 * 4 = 3 + 0.36 w against a threshold of 30.7, far under it for 10 and 40
  // steps; the 160-step window sums it up.
  ParameterChangeTest test{ParameterChangeTestOptions{}};
  const std::vector<Firing> firings = feed(test, 1000, 200, Eigen::Vector3d(0.3, 0.0, 0.0), 3);
  ASSERT_FALSE(firings.empty());
  EXPECT_GT(firings.front().step, 200);
  EXPECT_GT(firings.front().change.window, 10);
  EXPECT_GT(firings.front().change.jump[0], 0.0);
}

TEST(ParameterChangeTest, LeavesInactiveParametersOut) {
  // A jump of a parameter that is not tested (a constant, or a ligament already cut) is not
  // what the test looks for; the others' scores still carry its overlap, so it may fire, but
  // it never names the inactive one.
  ParameterChangeTest test{ParameterChangeTestOptions{}};
  const std::vector<Firing> firings =
      feed(test, 400, 100, Eigen::Vector3d(-2.0, 0.0, 0.0), 4, {false, true, true});
  for (const Firing& firing : firings) EXPECT_EQ(firing.change.jump[0], 0.0);
}

TEST(ParameterChangeTest, FollowsUpARecentChangeAtALowerThreshold) {
  // A jump of 0.12 log units on the first parameter (the rest of a change the filter is still
  // following): over 160 steps the joint T is about 3 + 160 * 0.0144 * 4 = 12 against 30.7,
  // silent; the first parameter alone, marked recently changed, has G^2 / V about
  // 1 + 9.2 against chi-square(1) at 1e-3, 10.8, and is found.
  const Eigen::Vector3d rest(0.12, 0.0, 0.0);
  ParameterChangeTest fresh{ParameterChangeTestOptions{}};
  EXPECT_TRUE(feed(fresh, 1000, 0, rest, 5).empty());
  ParameterChangeTest following{ParameterChangeTestOptions{}};
  const std::vector<Firing> firings = feed(following, 1000, 0, rest, 5, {true, true, true}, {true, false, false});
  ASSERT_FALSE(firings.empty());
  for (const Firing& firing : firings) {
    EXPECT_TRUE(firing.change.follow_up);
    EXPECT_GT(firing.change.jump[0], 0.0);
    EXPECT_EQ(firing.change.jump[1], 0.0);
    EXPECT_EQ(firing.change.jump[2], 0.0);
  }
}

TEST(ParameterChangeTest, TheFollowUpFiresAtItsRateWhileNothingChanges) {
  // White scores, the first parameter marked: at most its false alarm per window and step
  // (3 x 20000 x 1e-3 = 60; the windows overlap and restart after a firing, so fewer).
  ParameterChangeTest test{ParameterChangeTestOptions{}};
  const std::vector<Firing> firings = feed(test, 20000, 20000, Eigen::VectorXd::Zero(3), 6, {true, true, true},
                                           {true, false, false});
  EXPECT_LE(firings.size(), 60u);
  for (const Firing& firing : firings) EXPECT_EQ(firing.change.jump[1], 0.0);
}

}  // namespace
}  // namespace sigmafem
