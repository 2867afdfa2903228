// path_consistency on the exact Kalman filter of a scalar constant observed with Gaussian
// noise (the posterior mean is a martingale, so its Birge ratio is about 1), and on the same
// filter pulled by observations the model does not explain.
#include "filter/path_consistency.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace sigmafem {
namespace {

constexpr double kNoise = 0.5;

// The exact posterior of theta ~ N(0, 1) from y_k = theta + bias_k + e_k, e_k ~ N(0, kNoise^2):
// one EstimationStep per observation (theta and log_std the posterior mean and std).
std::vector<EstimationStep> kalman_path(double theta, const std::vector<double>& bias, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> noise(0.0, kNoise);
  double mean = 0.0, variance = 1.0;
  std::vector<EstimationStep> steps;
  for (double b : bias) {
    const double y = theta + b + noise(random);
    const double gain = variance / (variance + kNoise * kNoise);
    mean += gain * (y - mean);
    variance *= 1.0 - gain;
    EstimationStep step;
    step.theta = Eigen::VectorXd::Constant(1, mean);
    step.log_std = Eigen::VectorXd::Constant(1, std::sqrt(variance));
    steps.push_back(step);
  }
  return steps;
}

TEST(PathConsistency, ABirgeRatioOfOneOnAConsistentFilter) {
  // Over 200 runs of 2000 steps the mean of r^2 (chi-square over 20 intervals, divided by 20)
  // is 1 within 0.1 (its std there is 0.022).
  double sum = 0.0;
  for (unsigned seed = 1; seed <= 200; ++seed) {
    const PathConsistency path = path_consistency(kalman_path(0.3, std::vector<double>(2000, 0.0), seed), 0, 400);
    EXPECT_EQ(path.intervals, 20);
    sum += path.ratio * path.ratio;
  }
  EXPECT_NEAR(sum / 200.0, 1.0, 0.1);
}

TEST(PathConsistency, AnUnmodelledPullRaisesTheRatio) {
  // 50 steps at 3 noise std of bias (a recovering state after a change, say) pull the estimate
  // far more than the posterior variance that those steps remove allows.
  std::vector<double> bias(2000, 0.0);
  for (int k = 1150; k < 1200; ++k) bias[static_cast<std::size_t>(k)] = 3.0 * kNoise;
  int above = 0;
  for (unsigned seed = 1; seed <= 20; ++seed)
    above += path_consistency(kalman_path(0.3, bias, seed), 0, 400).ratio > 2.0;
  EXPECT_EQ(above, 20);
}

TEST(PathConsistency, NoEvidenceFromARunShorterThanItsIntervals) {
  const PathConsistency path = path_consistency(kalman_path(0.3, std::vector<double>(15, 0.0), 1), 0, 0);
  EXPECT_EQ(path.intervals, 0);
  EXPECT_EQ(path.ratio, 1.0);
}

}  // namespace
}  // namespace sigmafem
