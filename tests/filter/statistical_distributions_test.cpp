// The distribution functions against printed tables (3 decimals: Abramowitz and Stegun,
// tables 26.1, 26.8 and 26.10, as reproduced in any statistics text) and against identities.
#include "filter/statistical_distributions.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace sigmafem {
namespace {

constexpr double kTable = 6e-4;   // the tables round to 3 decimals

TEST(StatisticalDistributions, ChiSquareQuantilesMatchTheTables) {
  struct Row { double probability, dof, quantile; };
  const Row rows[] = {
      {0.95, 1, 3.841},    {0.95, 2, 5.991},   {0.95, 10, 18.307}, {0.95, 30, 43.773},
      {0.95, 100, 124.342}, {0.975, 30, 46.979}, {0.025, 30, 16.791}, {0.05, 30, 18.493},
      {0.025, 10, 3.247},  {0.999, 1, 10.828},  {0.99, 5, 15.086},  {0.005, 5, 0.412},
      {0.95, 40, 55.758},  {0.01, 1, 0.000157}};
  for (const Row& row : rows)
    EXPECT_NEAR(chi_square_quantile(row.probability, row.dof), row.quantile,
                row.quantile < 0.01 ? 1e-6 : kTable)
        << "chi-square quantile " << row.probability << " with " << row.dof << " dof";
  // Wilson-Hilferty alone is 2.4% low at 1 dof (3.75): the refinement on the exact cdf matters.
  EXPECT_NEAR(chi_square_tail_quantile(0.05, 1), 3.841459, 1e-6);
}

TEST(StatisticalDistributions, ChiSquareQuantileInvertsTheDistributionFarOut) {
  for (double dof : {1.0, 3.0, 12.0, 36.0, 720.0, 36000.0})
    for (double tail : {0.4, 0.025, 1e-3, 1e-6, 1e-10}) {
      const double upper = chi_square_tail_quantile(tail, dof);
      EXPECT_NEAR(chi_square_tail(upper, dof) / tail, 1.0, 1e-9) << "upper, " << dof << " dof, tail " << tail;
      const double lower = chi_square_quantile(tail, dof);
      EXPECT_NEAR(chi_square_cdf(lower, dof) / tail, 1.0, 1e-8) << "lower, " << dof << " dof, tail " << tail;
    }
  // 2 dof: the exponential distribution, tail exp(-x/2).
  EXPECT_NEAR(chi_square_tail(7.0, 2.0), std::exp(-3.5), 1e-15);
  EXPECT_NEAR(chi_square_cdf(7.0, 2.0) + chi_square_tail(7.0, 2.0), 1.0, 1e-15);
}

TEST(StatisticalDistributions, FQuantilesMatchTheTablesAndTheIdentities) {
  // Upper 5% and 1% points (Abramowitz and Stegun table 26.9).
  EXPECT_NEAR(f_tail_quantile(0.05, 5, 10), 3.326, 1e-3);
  EXPECT_NEAR(f_tail_quantile(0.01, 10, 20), 3.368, 1e-3);
  EXPECT_NEAR(f_tail_quantile(0.05, 2, 30), 3.316, 1e-3);
  // F(1, d) is t(d)^2; d1 F(d1, d2 -> infinity) is chi-square(d1).
  const double t = student_t_two_sided_quantile(0.05, 10);
  EXPECT_NEAR(f_tail_quantile(0.05, 1, 10), t * t, 1e-9);
  EXPECT_NEAR(360 * f_tail_quantile(1e-9, 360, 1e9) / chi_square_tail_quantile(1e-9, 360), 1.0, 1e-5);
  // Inverts the tail far out, where the change detector reads it.
  for (double tail : {0.3, 1e-3, 1e-9})
    EXPECT_NEAR(f_tail(f_tail_quantile(tail, 360, 360), 360, 360) / tail, 1.0, 1e-8) << tail;
}

TEST(StatisticalDistributions, NormalAndStudentTMatchTheTables) {
  EXPECT_NEAR(normal_quantile(0.975), 1.959964, 1e-6);
  EXPECT_NEAR(normal_quantile(0.005), -2.575829, 1e-6);
  EXPECT_NEAR(normal_tail(-normal_quantile(1e-9)), 1e-9, 1e-18);
  struct Row { double tail, dof, t; };
  const Row rows[] = {{0.05, 1, 12.706}, {0.05, 10, 2.228}, {0.05, 30, 2.042},
                      {0.01, 5, 4.032},  {0.01, 120, 2.617}, {0.2, 3, 1.638}};
  for (const Row& row : rows)
    EXPECT_NEAR(student_t_two_sided_quantile(row.tail, row.dof), row.t, kTable)
        << "t quantile, two-sided tail " << row.tail << " with " << row.dof << " dof";
  // Far out (a Bonferroni bound over 36 rows at 1/600): the quantile inverts the tail.
  const double t = student_t_two_sided_quantile(1e-2 / 6 / 36, 400);
  EXPECT_NEAR(student_t_two_sided_tail(t, 400) / (1e-2 / 6 / 36), 1.0, 1e-9);
  // With many dof, t is normal.
  EXPECT_NEAR(student_t_two_sided_quantile(0.05, 1e7), 1.959964, 1e-5);
}

TEST(StatisticalDistributions, BinomialTail) {
  EXPECT_NEAR(binomial_tail(3, 10, 0.5), 1.0 - 56.0 / 1024.0, 1e-14);   // 1 - C(10,0..2)/2^10
  EXPECT_NEAR(binomial_tail(10, 10, 0.5), 1.0 / 1024.0, 1e-15);
  EXPECT_EQ(binomial_tail(0, 10, 0.3), 1.0);
  EXPECT_EQ(binomial_tail(11, 10, 0.3), 0.0);
}

TEST(StatisticalDistributions, ChiBarSquareIsTheOneSidedSumOfSquares) {
  // L = 1: half the chi-square(1) tail (z > 0 half the time).
  EXPECT_NEAR(chi_bar_square_tail(3.841459, 1), 0.025, 1e-7);
  EXPECT_NEAR(chi_bar_square_tail(0.0, 10), 1.0 - std::ldexp(1.0, -10), 1e-15);
  EXPECT_EQ(chi_bar_square_tail(-1.0, 10), 1.0);
  for (double tail : {0.1, 1e-3, 1e-6})
    EXPECT_NEAR(chi_bar_square_tail(chi_bar_square_tail_quantile(tail, 10), 10), tail, 1e-9 * tail);
  // Against sampling: 200,000 sums of max(z, 0)^2 over 10 normals; the empirical tail at the
  // 5% and 1% quantiles within 4 binomial standard errors.
  std::mt19937_64 random(5);
  std::normal_distribution<double> normal;
  std::vector<double> sums(200000);
  for (double& s : sums) {
    s = 0.0;
    for (int k = 0; k < 10; ++k) s += std::pow(std::max(normal(random), 0.0), 2);
  }
  for (double tail : {0.05, 0.01}) {
    const double q = chi_bar_square_tail_quantile(tail, 10);
    const double above = static_cast<double>(std::count_if(sums.begin(), sums.end(), [q](double s) { return s > q; }));
    const double n = static_cast<double>(sums.size());
    EXPECT_NEAR(above / n, tail, 4.0 * std::sqrt(tail * (1 - tail) / n)) << "tail " << tail;
  }
}

}  // namespace
}  // namespace sigmafem
