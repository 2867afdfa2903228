// LigamentCutRule on estimate paths written by hand: a ligament is cut only after a change,
// only when its upper bound falls below 5% of its reference's lower bound, and only once; a
// ligament that merely weakens, or a wide estimate that could still be above the bound, is not.
#include "filter/ligament_cut.h"

#include <gtest/gtest.h>

#include <cmath>

namespace sigmafem {
namespace {

Eigen::VectorXd log_of(std::initializer_list<double> stiffness) {
  Eigen::VectorXd theta(static_cast<Eigen::Index>(stiffness.size()));
  Eigen::Index i = 0;
  for (double k : stiffness) theta[i++] = std::log(k);
  return theta;
}

TEST(LigamentCutRule, CutsOnlyALigamentThatLostNearlyAllItsStiffness) {
  LigamentCutRule rule(LigamentCutOptions{}, 3);
  const Eigen::VectorXd std_before = Eigen::VectorXd::Constant(3, 0.04);
  // Not armed: even a ligament at 1e-3 N/m is not cut.
  EXPECT_TRUE(rule.update(log_of({150, 1e-3, 200}), std_before).empty());

  rule.arm(log_of({150, 300, 200}), std_before);
  EXPECT_NEAR(rule.stiffness_before(1), 300.0, 1e-9);
  // 300 -> 25 N/m with a log std of 0.1: upper bound 25 e^0.2 = 30.5 N/m; the reference's lower
  // bound is 300 e^-0.08 = 277 N/m, 10% of it 27.7: not yet.
  EXPECT_TRUE(rule.update(log_of({150, 25, 200}), Eigen::Vector3d(0.04, 0.1, 0.04)).empty());
  // A wide estimate low in the middle could still lie above the bound (2 e^3 = 40 N/m): not cut.
  EXPECT_TRUE(rule.update(log_of({150, 2, 200}), Eigen::Vector3d(0.04, 1.5, 0.04)).empty());
  // The left ligament weakened to a third: not cut. The middle at 15 N/m, log std 0.2: upper
  // bound 22.4 N/m < 27.7: cut, with that bound.
  const std::vector<int> cut = rule.update(log_of({50, 15, 200}), Eigen::Vector3d(0.04, 0.2, 0.04));
  ASSERT_EQ(cut.size(), 1u);
  EXPECT_EQ(cut[0], 1);
  EXPECT_NEAR(rule.upper_bound(1), 15.0 * std::exp(0.4), 1e-9);
  EXPECT_TRUE(std::isnan(rule.upper_bound(0)));
  EXPECT_TRUE(rule.is_cut(1));
  EXPECT_FALSE(rule.is_cut(0));
  // Reported once.
  EXPECT_TRUE(rule.update(log_of({50, 1, 200}), Eigen::Vector3d(0.04, 0.2, 0.04)).empty());
}

TEST(LigamentCutRule, ALaterChangeReArmsForTheOthers) {
  LigamentCutRule rule(LigamentCutOptions{}, 2);
  const Eigen::VectorXd narrow = Eigen::VectorXd::Constant(2, 0.05);
  rule.arm(log_of({150, 300}), narrow);
  ASSERT_EQ(rule.update(log_of({150, 1}), narrow).size(), 1u);
  // The second change: the left ligament (at 150 N/m before it) is cut in its turn.
  rule.arm(log_of({150, 1}), narrow);
  const std::vector<int> cut = rule.update(log_of({2, 1}), narrow);
  ASSERT_EQ(cut.size(), 1u);
  EXPECT_EQ(cut[0], 0);
}

TEST(LigamentCutRule, DisabledNeverCuts) {
  LigamentCutOptions options;
  options.enabled = false;
  LigamentCutRule rule(options, 1);
  rule.arm(log_of({300}), Eigen::VectorXd::Constant(1, 0.05));
  EXPECT_TRUE(rule.update(log_of({1e-3}), Eigen::VectorXd::Constant(1, 0.05)).empty());
}

TEST(LigamentCutRule, RejectsAFractionOutsideZeroToOne) {
  LigamentCutOptions options;
  options.fraction = 1.5;
  EXPECT_THROW(LigamentCutRule(options, 1), std::invalid_argument);
  options.fraction = 0.05;
  options.remaining = 0.1;   // above the fraction: a cut ligament would not count as cut
  EXPECT_THROW(LigamentCutRule(options, 1), std::invalid_argument);
}

}  // namespace
}  // namespace sigmafem
