// gate_outliers (filter/outlier_gate.h): a point far outside its predicted band is left out, a
// consistent one is not (at about the stated false-alarm rate), the chi-square threshold takes
// the point's observed rows as its degrees of freedom, and many points off at once are a change,
// not outliers.
#include "filter/outlier_gate.h"

#include <gtest/gtest.h>

#include <random>

#include "filter/statistical_distributions.h"

namespace sigmafem {
namespace {

// Rows 0..3m-1 of m points, innovations z, variances 1.
struct Step {
  std::vector<int> rows;
  Eigen::VectorXd z, variance;
  explicit Step(int m) : z(Eigen::VectorXd::Zero(3 * m)), variance(Eigen::VectorXd::Ones(3 * m)) {
    for (int i = 0; i < 3 * m; ++i) rows.push_back(i);
  }
};

OutlierGateOptions enabled() {
  OutlierGateOptions options;
  options.enabled = true;
  return options;
}

TEST(OutlierGateTest, APointFarOutsideItsBandIsLeftOutAndOnlyWhenEnabled) {
  Step step(12);
  step.z.segment<3>(15) << 20.0, -5.0, 3.0;   // point 5, twenty standard deviations off
  EXPECT_EQ(gate_outliers(enabled(), step.rows, step.z, step.variance), std::vector<int>{5});
  EXPECT_TRUE(gate_outliers(OutlierGateOptions{}, step.rows, step.z, step.variance).empty())
      << "off by default";
  step.variance.segment<3>(15).setConstant(1e4);   // the filter expected a spread of 100
  EXPECT_TRUE(gate_outliers(enabled(), step.rows, step.z, step.variance).empty());
}

TEST(OutlierGateTest, TheThresholdIsTheChiSquareQuantileOfThePointsObservedRows) {
  const double two_rows = chi_square_tail_quantile(1e-6, 2.0);
  Step step(4);
  // Point 1 observed on two rows only (rows 3 and 5), just inside and just outside.
  step.rows = {0, 1, 2, 3, 5, 6, 7, 8, 9, 10, 11};
  step.z = Eigen::VectorXd::Zero(11);
  step.variance = Eigen::VectorXd::Ones(11);
  step.z[3] = std::sqrt(0.99 * two_rows);
  EXPECT_TRUE(gate_outliers(enabled(), step.rows, step.z, step.variance).empty());
  step.z[3] = std::sqrt(1.01 * two_rows);
  EXPECT_EQ(gate_outliers(enabled(), step.rows, step.z, step.variance), std::vector<int>{1});
}

TEST(OutlierGateTest, ManyPointsOffAtOnceAreAChangeNotOutliers) {
  Step step(12);
  for (int p = 0; p < 6; ++p) step.z[3 * p] = 50.0;   // half the points: still outliers
  EXPECT_EQ(gate_outliers(enabled(), step.rows, step.z, step.variance).size(), 6u);
  step.z[18] = 50.0;                                   // 7 of 12: a change
  EXPECT_TRUE(gate_outliers(enabled(), step.rows, step.z, step.variance).empty());
}

TEST(OutlierGateTest, AConsistentFilterLosesPointsAtTheFalseAlarmRate) {
  OutlierGateOptions options = enabled();
  options.false_alarm = 1e-3;
  std::mt19937 random(11);
  std::normal_distribution<double> normal;
  Step step(10);
  int rejected = 0;
  const int steps = 20000;
  for (int k = 0; k < steps; ++k) {
    for (Eigen::Index i = 0; i < step.z.size(); ++i) step.z[i] = normal(random);
    rejected += static_cast<int>(gate_outliers(options, step.rows, step.z, step.variance).size());
  }
  // 200 000 points at 1e-3: 200 expected, a binomial std of 14.
  EXPECT_GT(rejected, 150);
  EXPECT_LT(rejected, 250);
}

}  // namespace
}  // namespace sigmafem
