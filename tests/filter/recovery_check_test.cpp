// RecoveryCheck on synthetic innovations of 12 points: white, with a common mode shared by the
// points of a step (as H P^- H^T makes), and the same with a small bias on one axis.
#include "filter/recovery_check.h"

#include <gtest/gtest.h>

#include <random>

namespace sigmafem {
namespace {

constexpr int kPoints = 12;

// Feeds `steps` steps of standard-normal innovations (std 1 per row, a third of the variance
// common to the points of a step) plus `bias` on every y row; returns the number of steps at
// which recovered() was false once the window was full.
int biased_steps(int steps, double bias, unsigned seed) {
  RecoveryCheck check{RecoveryCheckOptions{}};
  std::mt19937 random(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::VectorXd std_dev = Eigen::VectorXd::Ones(3 * kPoints);
  int biased = 0;
  for (int k = 0; k < steps; ++k) {
    const double common[3] = {normal(random), normal(random), normal(random)};
    Eigen::VectorXd z(3 * kPoints);
    for (int i = 0; i < 3 * kPoints; ++i)
      z[i] = std::sqrt(1.0 / 3.0) * common[i % 3] + std::sqrt(2.0 / 3.0) * normal(random) + (i % 3 == 1 ? bias : 0.0);
    check.update(z, std_dev);
    if (k + 1 >= RecoveryCheckOptions{}.window && !check.recovered()) ++biased;
  }
  return biased;
}

TEST(RecoveryCheck, QuietOnWhiteInnovations) {
  // 20,000 tested windows at a false-alarm rate of 1e-3 per window: about 20 expected (the
  // windows overlap, so the count is lumpy); 60 would be three times the rate.
  EXPECT_LT(biased_steps(20000, 0.0, 1), 60);
}

TEST(RecoveryCheck, FindsABiasOfAFractionOfTheNoise) {
  // The step's mean over 12 points has std sqrt(1/3 + 2/36) = 0.62 here, 0.125 over 25 steps:
  // a bias of 0.8 std on every y row is t = 6.4 on average, far beyond the threshold (4.1).
  EXPECT_GT(biased_steps(2000, 0.8, 2), 1900);
}

TEST(RecoveryCheck, NotRecoveredBeforeItsWindowIsFull) {
  RecoveryCheck check{RecoveryCheckOptions{}};
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(3 * kPoints), one = Eigen::VectorXd::Ones(3 * kPoints);
  for (int k = 0; k + 1 < RecoveryCheckOptions{}.window; ++k) {
    check.update(zero, one);
    EXPECT_FALSE(check.recovered());
  }
}

}  // namespace
}  // namespace sigmafem
