// The adaptive observation noise (filter/adaptive_noise.h): its statistic is chi-square under
// the filter's own model, it stays at 1 on consistent innovations at its stated rate, it
// ignores what the parameters explain (a cut), and it holds the filter when a persistent model
// error would drive the parameters away.
#include "filter/adaptive_noise.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>

#include "filter/roukf.h"
#include "linear_gaussian_ensemble.h"

namespace sigmafem {
namespace {

std::vector<int> all_rows(int m) {
  std::vector<int> rows(static_cast<std::size_t>(m));
  for (int i = 0; i < m; ++i) rows[static_cast<std::size_t>(i)] = i;
  return rows;
}

Eigen::MatrixXd random_matrix(int rows, int cols, std::mt19937& engine) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd M(rows, cols);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < cols; ++j) M(i, j) = normal(engine);
  return M;
}

TEST(UnexplainedInnovation, IsWhatTheSensitivitiesCannotReach) {
  std::mt19937 engine(5);
  const int m = 12, p = 3;
  const Eigen::MatrixXd HL = random_matrix(m, p, engine);
  const double variance = 0.25;
  // In the span: nothing unexplained.
  const Eigen::VectorXd inside = HL * Eigen::Vector3d(1.0, -2.0, 0.5);
  UnexplainedInnovation u = unexplained_innovation(HL, inside, variance, all_rows(m), m);
  EXPECT_EQ(u.degrees_of_freedom, m - p);
  EXPECT_NEAR(u.chi_square, 0.0, 1e-20);
  // Orthogonal to the span: all of it.
  Eigen::VectorXd outside = random_matrix(m, 1, engine);
  outside -= HL * HL.colPivHouseholderQr().solve(outside);
  u = unexplained_innovation(HL, inside + outside, variance, all_rows(m), m);
  EXPECT_NEAR(u.chi_square, outside.squaredNorm() / variance, 1e-12);
  EXPECT_NEAR((u.residual - outside).norm(), 0.0, 1e-12);
  // A parameter the observations do not see spans nothing.
  Eigen::MatrixXd blind = HL;
  blind.col(2).setZero();
  EXPECT_EQ(unexplained_innovation(blind, inside, variance, all_rows(m), m).degrees_of_freedom, m - 2);
  // Rows not observed are NaN in the residual, on the data's row numbering.
  u = unexplained_innovation(HL.topRows(4), outside.head(4), variance, {1, 4, 7, 9}, 10);
  EXPECT_EQ(u.residual.size(), 10);
  EXPECT_TRUE(std::isnan(u.residual[0]));
  EXPECT_TRUE(std::isfinite(u.residual[4]));
}

TEST(AdaptiveNoise, StaysNominalOnConsistentInnovationsAtItsStatedRate) {
  // z ~ N(0, HL HL^T + sigma^2 I), a new HL at every step: the statistic is chi-square(m - p)
  // and lambda > 1 at a fraction of the steps near false_alarm (the windows overlap, so the
  // steps are not independent; the bound is for the rate, not for a run).
  std::mt19937 engine(11);
  std::normal_distribution<double> normal;
  const int m = 36, p = 3, steps = 40000;
  const double sigma = 0.5e-3;
  AdaptiveNoiseOptions options;
  options.false_alarm = 1e-3;   // larger than the default, so that the rate is measurable here
  AdaptiveNoise noise(options);
  int scaled = 0;
  double chi_square = 0.0;
  for (int k = 0; k < steps; ++k) {
    const Eigen::MatrixXd HL = 2e-3 * random_matrix(m, p, engine);
    Eigen::VectorXd z = HL * random_matrix(p, 1, engine);
    for (int i = 0; i < m; ++i) z[i] += sigma * normal(engine);
    const UnexplainedInnovation u = unexplained_innovation(HL, z, sigma * sigma, all_rows(m), m);
    chi_square += u.chi_square / u.degrees_of_freedom;
    scaled += noise.update(u) > 1.0;
  }
  EXPECT_NEAR(chi_square / steps, 1.0, 0.01);   // std of the mean: sqrt(2 / 33 / 40000) = 0.0012
  EXPECT_LT(static_cast<double>(scaled) / steps, 3.0 * options.false_alarm) << scaled << " steps scaled";
}

TEST(AdaptiveNoise, ScalesByTheErrorAndItsPersistence) {
  // A constant error of 10 sigma per row outside the sensitivities: lambda at least the
  // error's size ratio (about 100) times the persistence factor of rho near 1.
  std::mt19937 engine(3);
  std::normal_distribution<double> normal;
  const int m = 36, p = 3;
  const double sigma = 0.5e-3;
  const Eigen::MatrixXd HL = 2e-3 * random_matrix(m, p, engine);
  Eigen::VectorXd error = random_matrix(m, 1, engine);
  error -= HL * HL.colPivHouseholderQr().solve(error);
  error *= 10.0 * sigma * std::sqrt(static_cast<double>(m)) / error.norm();
  AdaptiveNoise noise({});
  double scale = 1.0;
  for (int k = 0; k < 20; ++k) {
    Eigen::VectorXd z = error;
    for (int i = 0; i < m; ++i) z[i] += sigma * normal(engine);
    scale = noise.update(unexplained_innovation(HL, z, sigma * sigma, all_rows(m), m));
  }
  EXPECT_GT(noise.ratio(), 80.0);
  EXPECT_GT(noise.correlation(), 0.95);
  EXPECT_GT(scale, noise.ratio() * 30.0);
  AdaptiveNoiseOptions off;
  off.enabled = false;
  AdaptiveNoise disabled(off);
  EXPECT_EQ(disabled.update(unexplained_innovation(HL, error, sigma * sigma, all_rows(m), m)), 1.0);
}

// The linear-Gaussian model of roukf_test with a constant error added to the observations
// outside what the parameters move: with the adaptive noise the estimate stays near its prior,
// without it the filter takes the error for information and runs away.
double parameter_excursion(bool adaptive) {
  std::mt19937 engine(7);
  std::normal_distribution<double> normal;
  const int n = 6, p = 2, m = 6, steps = 300;
  const Eigen::MatrixXd A = 0.9 * Eigen::MatrixXd::Identity(n, n);
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(n, p);
  B(0, 0) = 0.1;
  B(1, 1) = 0.1;
  const Eigen::MatrixXd H = Eigen::MatrixXd::Identity(m, n);
  const Eigen::VectorXd c = Eigen::VectorXd::Zero(n);
  const SigmaPoints points = make_sigma_points(SigmaPointSet::simplex, p);
  testing::LinearGaussianEnsemble ensemble(A, B, c, H, Eigen::VectorXd::Zero(n), points.count());
  RoukfOptions options;
  options.initial_theta = Eigen::VectorXd::Zero(p);
  options.initial_log_std = 1.0;
  options.parameter_drift_log_std = 0.035;
  options.observation_std = 0.01;
  options.adaptive_noise.enabled = adaptive;
  Roukf filter(options, ensemble);
  double excursion = 0.0;
  for (int k = 0; k < steps; ++k) {
    // The true parameters are 0 (the state stays 0); rows 0 to 2 carry a model error that
    // grows with time (a sag of 5 prior std), rows 0 and 1 of it along what the parameters
    // move: the wrong model's least-squares fit is theta = (5, 5).
    Eigen::VectorXd y(m);
    for (int i = 0; i < m; ++i) y[i] = 0.01 * normal(engine);
    const double sag = 5.0 * std::min(1.0, k / 50.0);
    y.head(3) += Eigen::Vector3d(sag, sag, -sag);
    filter.step(Eigen::Vector3d::Zero(), y);
    excursion = std::max(excursion, filter.theta().cwiseAbs().maxCoeff());
  }
  return excursion;
}

TEST(AdaptiveNoise, HoldsTheFilterUnderAPersistentModelError) {
  const double with = parameter_excursion(true), without = parameter_excursion(false);
  EXPECT_LT(with, 1.0) << "prior std is 1";
  EXPECT_GT(without, 4.0) << "the fit of the wrong model";
}

}  // namespace
}  // namespace sigmafem
