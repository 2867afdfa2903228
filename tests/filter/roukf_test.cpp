// The ROUKF against the exact Kalman filter on a linear-Gaussian model (docs/ROUKF.md: the
// anchors' star variant was fragile; both sets are tested against the exact answer).
#include "filter/roukf.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "linear_gaussian_ensemble.h"

namespace sigmafem {
namespace {

// On a linear model the ROUKF is exact; what remains is rounding in p x p and n x p algebra
// over a few dozen steps, well under 1e-8 relative.
constexpr double kExact = 1e-8;

struct LinearModel {
  Eigen::MatrixXd A, B, H;
  Eigen::VectorXd c, x0, theta_true;
};

LinearModel make_linear_model(int n, int p, int m, unsigned seed) {
  std::mt19937 engine(seed);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  auto random = [&](int rows, int cols) {
    Eigen::MatrixXd M(rows, cols);
    for (int i = 0; i < rows; ++i)
      for (int j = 0; j < cols; ++j) M(i, j) = uniform(engine);
    return M;
  };
  LinearModel model;
  model.A = 0.9 * Eigen::MatrixXd::Identity(n, n) + 0.05 * random(n, n);   // stable
  model.B = 0.3 * random(n, p);
  model.H = random(m, n);
  model.c = random(n, 1);
  model.x0 = random(n, 1);
  model.theta_true = random(p, 1);
  return model;
}

class RoukfExactTest : public ::testing::TestWithParam<SigmaPointSet> {
 protected:
  // What every test's filter starts from: the set under test, theta_hat = 0.
  RoukfOptions options(int p, double prior_std, double observation_std) const {
    RoukfOptions o;
    o.sigma_points = GetParam();
    o.initial_theta = Eigen::VectorXd::Zero(p);
    o.initial_log_std = prior_std;
    o.observation_std = observation_std;
    return o;
  }
};

TEST_P(RoukfExactTest, MatchesTheExactKalmanFilterStepAfterStep) {
  const int n = 6, p = 3, m = 4, steps = 40;
  const double sigma0 = 0.7, obs_std = 0.05;
  const LinearModel model = make_linear_model(n, p, m, 3);
  const SigmaPoints points = make_sigma_points(GetParam(), p);
  testing::LinearGaussianEnsemble ensemble(model.A, model.B, model.c, model.H, model.x0,
                                           points.count());
  const RoukfOptions options = this->options(p, sigma0, obs_std);
  Roukf filter(options, ensemble);

  // The exact filter on z = [x; theta]: F = [A B; 0 I], observation [H 0].
  Eigen::MatrixXd F = Eigen::MatrixXd::Identity(n + p, n + p);
  F.topLeftCorner(n, n) = model.A;
  F.topRightCorner(n, p) = model.B;
  Eigen::MatrixXd Ha = Eigen::MatrixXd::Zero(m, n + p);
  Ha.leftCols(n) = model.H;
  Eigen::VectorXd z(n + p);
  z << model.x0, options.initial_theta;
  Eigen::MatrixXd P = Eigen::MatrixXd::Zero(n + p, n + p);
  P.bottomRightCorner(p, p) = sigma0 * sigma0 * Eigen::MatrixXd::Identity(p, p);
  const Eigen::MatrixXd R = obs_std * obs_std * Eigen::MatrixXd::Identity(m, m);

  // Data from the true parameters, with noise.
  std::mt19937 engine(11);
  std::normal_distribution<double> noise(0.0, obs_std);
  Eigen::VectorXd x_true = model.x0;
  for (int k = 1; k <= steps; ++k) {
    const Eigen::Vector3d so(std::sin(0.3 * k), 0.0, 0.0);
    x_true = model.A * x_true + model.B * model.theta_true + model.c * so.x();
    Eigen::VectorXd y = model.H * x_true;
    for (int i = 0; i < m; ++i) y[i] += noise(engine);

    Eigen::VectorXd u = Eigen::VectorXd::Zero(n + p);
    u.head(n) = model.c * so.x();
    z = F * z + u;
    P = F * P * F.transpose();
    const Eigen::MatrixXd S = Ha * P * Ha.transpose() + R;
    const Eigen::MatrixXd K = P * Ha.transpose() * S.inverse();
    const Eigen::VectorXd innovation = y - Ha * z;
    const double exact_nis = innovation.dot(S.ldlt().solve(innovation));
    z += K * innovation;
    P = (Eigen::MatrixXd::Identity(n + p, n + p) - K * Ha) * P;

    const RoukfStep result = filter.step(so, y);
    const Eigen::VectorXd theta_exact = z.tail(p);
    const Eigen::MatrixXd P_theta_exact = P.bottomRightCorner(p, p);
    EXPECT_LT((result.theta - theta_exact).norm(), kExact * (1.0 + theta_exact.norm()))
        << to_string(GetParam()) << " step " << k << ": theta";
    EXPECT_LT((result.theta_covariance - P_theta_exact).norm(), kExact * P_theta_exact.norm())
        << to_string(GetParam()) << " step " << k << ": parameter covariance";
    const Eigen::VectorXd x_hat =
        ensemble.estimate(points.alpha, points.directions, filter.last_correction());
    EXPECT_LT((x_hat - z.head(n)).norm(), kExact * (1.0 + z.head(n).norm()))
        << to_string(GetParam()) << " step " << k << ": state";
    EXPECT_NEAR(result.normalised_innovation, exact_nis, kExact * (1.0 + exact_nis))
        << to_string(GetParam()) << " step " << k << ": normalised innovation squared";
    // What the residual diagnostics keep: the innovation and diag(S), row by row.
    ASSERT_EQ(result.innovation_variance.size(), m);
    EXPECT_LT((result.innovation - innovation).norm(), kExact * (1.0 + innovation.norm()))
        << to_string(GetParam()) << " step " << k << ": innovation";
    EXPECT_LT((result.innovation_variance - S.diagonal()).norm(), kExact * S.diagonal().norm())
        << to_string(GetParam()) << " step " << k << ": diagonal of the innovation covariance";
  }
  // And the filter learnt something: theta moved towards the truth.
  EXPECT_LT((filter.theta() - model.theta_true).norm(), 0.5 * model.theta_true.norm());
}

TEST_P(RoukfExactTest, DriftAddsItsVarianceToTheParameters) {
  const int n = 4, p = 2, m = 3;
  const LinearModel model = make_linear_model(n, p, m, 5);
  const SigmaPoints points = make_sigma_points(GetParam(), p);
  testing::LinearGaussianEnsemble ensemble(model.A, model.B, model.c, model.H, model.x0,
                                           points.count());
  RoukfOptions options = this->options(p, 0.5, 0.1);
  options.parameter_drift_log_std = 0.2;
  Roukf filter(options, ensemble);
  const Eigen::MatrixXd before = filter.theta_covariance();
  // No observation at all: the step is prediction only, so P_theta grows by exactly q^2 I.
  const Eigen::VectorXd nothing = Eigen::VectorXd::Constant(m, NAN);
  const RoukfStep result = filter.step(Eigen::Vector3d::Zero(), nothing);
  EXPECT_EQ(result.observed_rows, 0);
  EXPECT_TRUE(std::isnan(result.innovation_rms));
  const Eigen::MatrixXd expected = before + 0.04 * Eigen::MatrixXd::Identity(p, p);
  EXPECT_LT((result.theta_covariance - expected).norm(), kExact)
      << to_string(GetParam()) << ": P_theta after a drift step without data";
}

TEST_P(RoukfExactTest, TheScoreIsTheSensitivitiesTimesTheInnovation) {
  // First step from the known x0: y = H (A x0 + B theta + c u), so the sensitivity of the
  // predicted observation to theta is H B exactly, and with P = s^2 I and R = r I the score
  // is (HB)^T z / r with covariance (HB)^T (HB P (HB)^T + R) HB / r^2
  // (filter/parameter_change_test.h).
  const int n = 5, p = 3, m = 4;
  const LinearModel model = make_linear_model(n, p, m, 11);
  const SigmaPoints points = make_sigma_points(GetParam(), p);
  testing::LinearGaussianEnsemble ensemble(model.A, model.B, model.c, model.H, model.x0, points.count());
  const double s = 0.5, sigma = 0.1;
  Roukf filter(options(p, s, sigma), ensemble);
  const Eigen::Vector3d so(0.3, 0.0, 0.0);
  const Eigen::VectorXd x1 = model.A * model.x0 + model.B * model.theta_true + model.c * so.x();
  const Eigen::VectorXd y = model.H * x1;
  const RoukfStep result = filter.step(so, y);
  const Eigen::MatrixXd HB = model.H * model.B;
  const Eigen::VectorXd z = y - model.H * (model.A * model.x0 + model.c * so.x());   // theta_hat = 0
  const double r = sigma * sigma;
  const Eigen::VectorXd score = HB.transpose() * z / r;
  const Eigen::MatrixXd S = s * s * HB * HB.transpose() + r * Eigen::MatrixXd::Identity(m, m);
  const Eigen::MatrixXd covariance = HB.transpose() * S * HB / (r * r);
  EXPECT_LT((result.score - score).norm(), kExact * score.norm()) << to_string(GetParam());
  EXPECT_LT((result.score_covariance - covariance).norm(), kExact * covariance.norm()) << to_string(GetParam());
}

TEST_P(RoukfExactTest, OpeningAddsTheCovarianceButNotToAFixedParameter) {
  const int n = 4, p = 3, m = 3;
  const LinearModel model = make_linear_model(n, p, m, 12);
  const SigmaPoints points = make_sigma_points(GetParam(), p);
  testing::LinearGaussianEnsemble ensemble(model.A, model.B, model.c, model.H, model.x0, points.count());
  Roukf filter(options(p, 0.5, 0.1), ensemble);
  filter.fix(2, 0.0);
  EXPECT_EQ(filter.changeable(), (std::vector<bool>{true, true, false}));
  const Eigen::MatrixXd before = filter.theta_covariance();
  Eigen::MatrixXd opened(p, p);
  opened << 0.09, 0.03, 0.02, 0.03, 0.04, 0.01, 0.02, 0.01, 0.05;
  filter.open(opened);
  const RoukfStep result = filter.step(Eigen::Vector3d::Zero(), Eigen::VectorXd::Constant(m, NAN));
  Eigen::MatrixXd expected = before;
  expected.topLeftCorner(2, 2) += opened.topLeftCorner(2, 2);   // the fixed row and column stay
  EXPECT_LT((result.theta_covariance - expected).norm(), kExact) << to_string(GetParam());
  EXPECT_THROW(filter.open(Eigen::MatrixXd::Identity(2, 2)), std::invalid_argument);
}

TEST_P(RoukfExactTest, InflationLeavesTheConstantsAlone) {
  const int n = 4, p = 3, m = 3;
  const LinearModel model = make_linear_model(n, p, m, 7);
  const SigmaPoints points = make_sigma_points(GetParam(), p);
  testing::LinearGaussianEnsemble ensemble(model.A, model.B, model.c, model.H, model.x0,
                                           points.count());
  RoukfOptions options = this->options(p, 0.5, 0.1);
  options.constant = {false, true, false};
  Roukf filter(options, ensemble);
  const Eigen::MatrixXd before = filter.theta_covariance();
  filter.inflate(0.3);
  const RoukfStep result = filter.step(Eigen::Vector3d::Zero(), Eigen::VectorXd::Constant(m, NAN));
  const Eigen::MatrixXd expected = before + Eigen::Vector3d(0.09, 0.0, 0.09).asDiagonal().toDenseMatrix();
  EXPECT_LT((result.theta_covariance - expected).norm(), kExact)
      << to_string(GetParam()) << ": only the parameters that are not constants open";
}

TEST_P(RoukfExactTest, HeldConstantsStayWhileTheOthersAreCorrected) {
  const int n = 6, p = 3, m = 4;
  const LinearModel model = make_linear_model(n, p, m, 11);
  const SigmaPoints points = make_sigma_points(GetParam(), p);
  testing::LinearGaussianEnsemble ensemble(model.A, model.B, model.c, model.H, model.x0,
                                           points.count());
  testing::LinearGaussianEnsemble truth(model.A, model.B, model.c, model.H, model.x0, 1);
  RoukfOptions options = this->options(p, 0.7, 0.05);
  options.constant = {false, false, true};
  Roukf filter(options, ensemble);
  truth.set_parameters(model.theta_true);
  filter.hold_constants(true);
  for (int k = 1; k <= 10; ++k) {
    truth.advance(Eigen::Vector3d::Zero());
    Eigen::MatrixXd y;
    truth.predicted_observations(y);
    const RoukfStep result = filter.step(Eigen::Vector3d::Zero(), y.col(0));
    EXPECT_NEAR(result.theta[2], 0.0, 1e-12) << to_string(GetParam()) << ": the held constant moved at step " << k;
  }
  EXPECT_GT(filter.theta().head(2).norm(), 0.1) << "the other parameters were not corrected";
  filter.hold_constants(false);
  truth.advance(Eigen::Vector3d::Zero());
  Eigen::MatrixXd y;
  truth.predicted_observations(y);
  EXPECT_GT(std::abs(filter.step(Eigen::Vector3d::Zero(), y.col(0)).theta[2]), 1e-6) << "released, it is corrected again";
}

TEST_P(RoukfExactTest, MissingRowsAreDropped) {
  // A step where some rows are missing equals the exact filter with those rows removed:
  // compare against a second filter fed a model whose H lacks the rows.
  const int n = 5, p = 2, m = 4;
  const LinearModel model = make_linear_model(n, p, m, 9);
  const SigmaPoints points = make_sigma_points(GetParam(), p);
  Eigen::MatrixXd H_kept(2, n);
  H_kept << model.H.row(0), model.H.row(2);
  testing::LinearGaussianEnsemble with_gaps(model.A, model.B, model.c, model.H, model.x0,
                                            points.count());
  testing::LinearGaussianEnsemble reduced(model.A, model.B, model.c, H_kept, model.x0,
                                          points.count());
  RoukfOptions options;
  options.sigma_points = GetParam();
  options.initial_theta = Eigen::VectorXd::Zero(p);
  options.observation_std = 0.1;
  Roukf filter_gaps(options, with_gaps), filter_reduced(options, reduced);
  for (int k = 1; k <= 10; ++k) {
    Eigen::VectorXd y = model.H * model.x0 * (1.0 + 0.1 * k);
    Eigen::VectorXd y_kept(2);
    y_kept << y[0], y[2];
    y[1] = NAN;
    y[3] = NAN;
    const RoukfStep a = filter_gaps.step(Eigen::Vector3d(0.1 * k, 0, 0), y);
    const RoukfStep b = filter_reduced.step(Eigen::Vector3d(0.1 * k, 0, 0), y_kept);
    EXPECT_EQ(a.observed_rows, 2);
    EXPECT_LT((a.theta - b.theta).norm(), 1e-12) << "step " << k;
  }
}

INSTANTIATE_TEST_SUITE_P(BothSets, RoukfExactTest,
                         ::testing::Values(SigmaPointSet::simplex, SigmaPointSet::star),
                         [](const auto& param_info) { return std::string(to_string(param_info.param)); });

}  // namespace
}  // namespace sigmafem
