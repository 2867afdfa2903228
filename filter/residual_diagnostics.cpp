#include "filter/residual_diagnostics.h"

#include <Eigen/QR>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <stdexcept>

#include "filter/rigid_fit.h"
#include "filter/statistical_distributions.h"

namespace sigmafem {
namespace {

constexpr int kTestCount = 6;        // the verdict's tests; each gets false_alarm / kTestCount
constexpr int kMinRowValues = 10;    // a row needs this many values for its own statistics
constexpr double kRowLjungBoxTailExcess = 3.0;   // see whiteness_tests
constexpr double kConservativeS = 0.1;           // see nis_tests
constexpr int kDetrendSteps = 100;               // see whiteness_tests
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
const char* const kAxes = "xyz";

std::string format(const char* pattern, double a, double b = 0.0, double c = 0.0, double d = 0.0) {
  char text[256];
  std::snprintf(text, sizeof text, pattern, a, b, c, d);
  return text;
}

std::string row_name(int row) {
  return "point " + std::to_string(row / 3) + " axis " + kAxes[row % 3];
}

// Root mean square over the finite entries (NaN when there is none).
double finite_rms(const Eigen::VectorXd& v) {
  double sum = 0.0;
  int count = 0;
  for (Eigen::Index i = 0; i < v.size(); ++i)
    if (std::isfinite(v[i])) {
      sum += v[i] * v[i];
      ++count;
    }
  return count ? std::sqrt(sum / count) : kNan;
}

// The effective number of independent values in a series with lag-1 autocorrelation rho >= 0
// (AR(1): n (1 - rho) / (1 + rho)), from the consecutive pairs of finite values of `x` minus
// `mean`. The innovations of a filter that is still settling (an estimate converging from its
// prior, or following a cut by drift) are correlated over many steps; a t-test that took them
// for independent called a consistent model biased (measured: rigid_bias failed on 1 of 8
// clean liver_diagnose seeds, at a 0.17% level).
double effective_count(const Eigen::VectorXd& x, double mean, double count) {
  double c0 = 0.0, c1 = 0.0;
  for (Eigen::Index t = 0; t < x.size(); ++t) {
    if (!std::isfinite(x[t])) continue;
    const double a = x[t] - mean;
    c0 += a * a;
    if (t > 0 && std::isfinite(x[t - 1])) c1 += a * (x[t - 1] - mean);
  }
  const double rho = c0 > 0.0 ? std::clamp(c1 / c0, 0.0, 0.99) : 0.0;
  return std::max(2.0, count * (1.0 - rho) / (1.0 + rho));
}

Eigen::MatrixX3d as_points(const Eigen::VectorXd& rows) {
  Eigen::MatrixX3d points(rows.size() / 3, 3);
  for (Eigen::Index j = 0; j < points.rows(); ++j) points.row(j) = rows.segment<3>(3 * j).transpose();
  return points;
}

void nis_tests(const InnovationSeries& series, const std::vector<int>& used, double level,
               ResidualDiagnostics& d) {
  NisDiagnostics& nis = d.nis;
  const double N = static_cast<double>(used.size());
  double total = 0.0, dof = 0.0;
  std::map<int, std::pair<double, double>> band_of_dof;   // chi^2(m) 95% band, m -> (low, high)
  for (int k : used) {
    const double value = series.normalised_innovation[k];
    const int m = series.observed_rows[static_cast<std::size_t>(k)];
    total += value;
    dof += m;
    auto band = band_of_dof.find(m);
    if (band == band_of_dof.end())
      band = band_of_dof.emplace(m, std::make_pair(chi_square_quantile(0.025, m),
                                                   chi_square_tail_quantile(0.025, m))).first;
    nis.step_band_low.push_back(band->second.first);
    nis.step_band_high.push_back(band->second.second);
    if (value > band->second.second) ++nis.steps_above;
  }
  nis.mean = total / N;
  nis.mean_dof = dof / N;
  // A missing effect adds innovation and raises the NIS. A NIS below its expectation means the
  // filter overstates its uncertainty, and the random-walk drift makes S conservative by
  // design (measured: mean NIS 35.2-35.9 against 36 over box.json seeds 1-10, on average 1.5
  // std of the mean below it, which the plain two-sided band failed 1 time in 10). So the
  // lower bound lets S overstate the innovation variance by up to kConservativeS (10%); an
  // observation_std set well above the data's noise still fails it.
  nis.band_low = (1.0 - kConservativeS) * chi_square_quantile(0.5 * level, dof) / N;
  nis.band_high = chi_square_tail_quantile(0.5 * level, dof) / N;
  nis.band95_low = chi_square_quantile(0.025, dof) / N;
  nis.band95_high = chi_square_tail_quantile(0.025, dof) / N;
  nis.p_value = std::min(1.0, 2.0 * std::min(chi_square_cdf(total, dof), chi_square_tail(total, dof)));
  nis.fraction_above = nis.steps_above / N;
  // Steps whose NIS lies above their band: a model error that comes and goes (outliers, a
  // missing effect felt at some steps) shows here before it moves the mean. Only the upper
  // side: a NIS below the band says S overstates the innovation, which the drift does by
  // design and nis_mean bounds (up to kConservativeS). Counting that side too, the true model
  // of the liver under 9.81 m/s^2 along y (seed 2) failed with 117 steps outside (115
  // accepted), 71 of them below the band (43 expected) and 46 above (43 expected), while its
  // mean NIS was 34.7, 3.5% conservative. The count above is Binomial(N, 0.025) for a
  // consistent filter: accept up to the largest count c with P(X > c) above the level.
  const int n = static_cast<int>(used.size());
  nis.max_above = static_cast<int>(0.025 * n);
  while (nis.max_above < n && binomial_tail(nis.max_above + 1, n, 0.025) > level) ++nis.max_above;

  DiagnosticTest mean;
  mean.name = "nis_mean";
  mean.statistic = nis.mean;
  mean.accept_low = nis.band_low;
  mean.accept_high = nis.band_high;
  mean.p_value = nis.p_value;
  mean.level = level;
  mean.passed = nis.mean >= nis.band_low && nis.mean <= nis.band_high;
  mean.detail = format("mean NIS %.4g over %.0f steps, expected %.4g (the mean number of observed "
                       "rows); accepted ",
                       nis.mean, N, nis.mean_dof) +
                format("%.4g..%.4g (the low end allows a 10%% conservative S)", nis.band_low, nis.band_high);
  d.verdict.tests.push_back(mean);

  DiagnosticTest above;
  above.name = "nis_above_band";
  above.statistic = nis.steps_above;
  above.accept_low = kNan;
  above.accept_high = nis.max_above;
  above.p_value = binomial_tail(nis.steps_above, n, 0.025);
  above.level = level;
  above.passed = nis.steps_above <= nis.max_above;
  above.detail = format("%.0f of %.0f steps (%.1f%%) have their NIS above the 95%% chi-square "
                        "band (2.5%% expected); accepted up to %.0f",
                        nis.steps_above, N, 100.0 * nis.fraction_above, nis.max_above);
  d.verdict.tests.push_back(above);
}

// The centred moving average of the finite values of x over `window` steps (fewer at the
// ends), by prefix sums; NaN where no value is in reach.
Eigen::VectorXd moving_average(const Eigen::VectorXd& x, int window) {
  const Eigen::Index N = x.size(), half = window / 2;
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(N + 1), count = Eigen::VectorXd::Zero(N + 1);
  for (Eigen::Index t = 0; t < N; ++t) {
    const bool finite = std::isfinite(x[t]);
    sum[t + 1] = sum[t] + (finite ? x[t] : 0.0);
    count[t + 1] = count[t] + (finite ? 1.0 : 0.0);
  }
  Eigen::VectorXd mean(N);
  for (Eigen::Index t = 0; t < N; ++t) {
    const Eigen::Index a = std::max<Eigen::Index>(0, t - half), b = std::min<Eigen::Index>(N, t + half + 1);
    const double n = count[b] - count[a];
    mean[t] = n > 0.0 ? (sum[b] - sum[a]) / n : kNan;
  }
  return mean;
}

// X: N x n standardised innovations (NaN = missing).
void whiteness_tests(const Eigen::MatrixXd& X, int max_lag, double level, ResidualDiagnostics& d) {
  WhitenessDiagnostics& w = d.whiteness;
  const Eigen::Index N = X.rows(), n = X.cols();
  const int L = std::max(1, std::min(max_lag, static_cast<int>(N / 5)));
  w.max_lag = L;
  w.row_ljung_box.assign(static_cast<std::size_t>(n), kNan);
  w.row_p_value.assign(static_cast<std::size_t>(n), kNan);

  // Each usable row demeaned (so that a bias does not read as correlation), missing values
  // set to zero so that sums over products skip them; `observed` marks the others. For the
  // per-row test, X0_local: each row less its local mean instead, a centred moving average over
  // kDetrendSteps, so that a slow drift of the mean does not read as correlation at lags 1..L
  // either. Slow drifts are the bias tests' business: a filter following a cut by drift moves
  // its innovations' mean over hundreds of steps, which the per-row Ljung-Box test read as
  // colour (box.json seed 1, the default demo: 40.67 against 40.23 at the row nearest the cut;
  // 1 of 10 seeds). The local mean biases each lag's correlation by about -1/kDetrendSteps:
  // nothing against one row's threshold, but far more than the band of the average over rows,
  // which therefore keeps the plain mean.
  std::vector<Eigen::Index> rows;
  for (Eigen::Index i = 0; i < n; ++i)
    if (X.col(i).array().isFinite().count() >= std::max(kMinRowValues, L + 2)) rows.push_back(i);
  const Eigen::Index nv = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd X0 = Eigen::MatrixXd::Zero(N, nv), observed = Eigen::MatrixXd::Zero(N, nv);
  Eigen::MatrixXd X0_local = Eigen::MatrixXd::Zero(N, nv);
  Eigen::VectorXd count(nv);
  for (Eigen::Index c = 0; c < nv; ++c) {
    const Eigen::VectorXd column = X.col(rows[static_cast<std::size_t>(c)]);
    const Eigen::Array<bool, Eigen::Dynamic, 1> finite = column.array().isFinite();
    count[c] = static_cast<double>(finite.count());
    const double mean = finite.select(column.array(), 0.0).sum() / count[c];
    const Eigen::VectorXd local_mean = moving_average(column, kDetrendSteps);
    for (Eigen::Index t = 0; t < N; ++t)
      if (finite[t]) {
        X0(t, c) = column[t] - mean;
        X0_local(t, c) = column[t] - local_mean[t];
        observed(t, c) = 1.0;
      }
  }

  // Per-row autocorrelation r_ik = c_k / c_0 (the usual 1/N normalisation at every lag) and
  // the row's one-sided Ljung-Box Q+ = N(N+2) sum_k max(r_k, 0)^2 / (N-k), chi-bar-square of L
  // when white. One-sided because a missing effect leaves an error that persists from step to
  // step (positive correlation), while a negative lag-1 correlation is a filter that corrects
  // more than the data need: its parameter drift, there so that it can follow a change, is
  // larger than a constant truth's. Measured on the shipped liver under a declared 9.81 m/s^2
  // (the true model): lag 1 -0.029 against a band of 0.008 with the scenario's drift of 0.035,
  // -0.015 with 0.01 and +0.001 with 0.0035, every other lag inside its band; the two-sided
  // test called the true model inconsistent. The negative lags stay in the report.
  w.autocorrelation.assign(static_cast<std::size_t>(L), 0.0);
  int averaged = 0;
  for (Eigen::Index c = 0; c < nv; ++c) {
    const double c0 = X0.col(c).squaredNorm(), c0_local = X0_local.col(c).squaredNorm();
    if (!(c0 > 0.0) || !(c0_local > 0.0)) continue;
    const double Ni = count[c];
    double q = 0.0;
    for (int k = 1; k <= L; ++k) {
      w.autocorrelation[static_cast<std::size_t>(k - 1)] += X0.col(c).head(N - k).dot(X0.col(c).tail(N - k)) / c0;
      const double r = X0_local.col(c).head(N - k).dot(X0_local.col(c).tail(N - k)) / c0_local;
      if (r > 0.0) q += r * r / (Ni - k);
    }
    q *= Ni * (Ni + 2.0);
    const auto row = static_cast<std::size_t>(rows[static_cast<std::size_t>(c)]);
    w.row_ljung_box[row] = q;
    w.row_p_value[row] = chi_bar_square_tail(q, L);
    ++averaged;
  }
  for (double& r : w.autocorrelation) r /= std::max(1, averaged);

  // The rows are correlated with each other (through H P^- H^T, and through whatever the model
  // misses), so the average over n rows has the variance of fewer independent ones: for
  // series white in time with correlation C_ij, var(mean_i r_ik) = sum_ij C_ij^2 / (n^2 N)
  // (Bartlett). Sample correlations overstate |C_ij| slightly, so this errs on the safe side.
  const Eigen::MatrixXd cross = X0.transpose() * X0;                                // sum x_i x_j
  const Eigen::MatrixXd power = X0.cwiseAbs2().transpose() * observed;              // sum x_i^2 [j seen]
  double sum_c2 = 0.0;
  for (Eigen::Index i = 0; i < nv; ++i)
    for (Eigen::Index j = 0; j < nv; ++j) {
      const double norm = power(i, j) * power(j, i);
      if (norm > 0.0) sum_c2 += cross(i, j) * cross(i, j) / norm;
    }
  w.effective_rows = sum_c2 > 0.0 ? static_cast<double>(nv) * static_cast<double>(nv) / sum_c2 : 1.0;
  const double Nd = static_cast<double>(N);
  w.band = 1.96 / std::sqrt(Nd * w.effective_rows);
  double q = 0.0;
  for (int k = 1; k <= L; ++k) {
    const double r = w.autocorrelation[static_cast<std::size_t>(k - 1)];
    if (r > 0.0) q += r * r / (Nd - k);   // one-sided, as per row
  }
  w.ljung_box = w.effective_rows * Nd * (Nd + 2.0) * q;
  w.p_value = chi_bar_square_tail(w.ljung_box, L);

  DiagnosticTest average;
  average.name = "whiteness";
  average.statistic = w.ljung_box;
  average.accept_low = kNan;
  average.accept_high = chi_bar_square_tail_quantile(level, L);
  average.p_value = w.p_value;
  average.level = level;
  average.passed = w.ljung_box <= average.accept_high;
  average.detail = format("one-sided Ljung-Box %.4g on the autocorrelation averaged over rows (lags 1..%.0f, "
                          "lag 1: %.3f, 95%% band +-%.3f)",
                          w.ljung_box, L, w.autocorrelation[0], w.band) +
                   format("; accepted up to %.4g (%.1f effective rows)", average.accept_high, w.effective_rows);
  d.verdict.tests.push_back(average);

  // Per row, Bonferroni over the rows tested: one coloured row is found even when the
  // average hides it. So far out (p near 1e-5) Ljung-Box's chi-square tail is too thin for a
  // few hundred steps: on white Gaussian rows of 450 steps, p < 1e-4 came 2.8 times as often as
  // it should (144,000 rows). The test runs at a third of its share to stay within it.
  w.row_p_threshold = (averaged > 0 ? level / averaged : level) / kRowLjungBoxTailExcess;
  const double q_threshold = chi_bar_square_tail_quantile(w.row_p_threshold, L);
  DiagnosticTest per_row;
  per_row.name = "whiteness_rows";
  per_row.accept_low = kNan;
  per_row.accept_high = q_threshold;
  per_row.level = level;
  per_row.p_value = 1.0;
  int worst = -1;
  for (std::size_t i = 0; i < w.row_ljung_box.size(); ++i) {
    if (std::isnan(w.row_ljung_box[i])) continue;
    if (w.row_ljung_box[i] > q_threshold) w.flagged_rows.push_back(static_cast<int>(i));
    if (worst < 0 || w.row_ljung_box[i] > per_row.statistic) {
      per_row.statistic = w.row_ljung_box[i];
      per_row.p_value = w.row_p_value[i];
      worst = static_cast<int>(i);
    }
  }
  per_row.passed = w.flagged_rows.empty();
  per_row.detail = format("%.0f of %.0f rows not white (one-sided Ljung-Box above %.4g, p < %.2g)",
                          static_cast<double>(w.flagged_rows.size()), averaged, q_threshold,
                          w.row_p_threshold) +
                   (worst >= 0 ? "; largest at " + row_name(worst) + format(": %.4g", per_row.statistic)
                               : std::string());
  d.verdict.tests.push_back(per_row);
}

// Z: N x n raw innovations (NaN = missing).
void bias_tests(const Eigen::MatrixXd& Z, double level, ResidualDiagnostics& d) {
  BiasDiagnostics& b = d.bias;
  const Eigen::Index n = Z.cols();
  b.mean = Eigen::VectorXd::Constant(n, kNan);
  b.standard_error = Eigen::VectorXd::Constant(n, kNan);
  b.t = Eigen::VectorXd::Constant(n, kNan);
  b.t_threshold = Eigen::VectorXd::Constant(n, kNan);
  b.count = Eigen::VectorXi::Zero(n);
  int tested = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Array<bool, Eigen::Dynamic, 1> finite = Z.col(i).array().isFinite();
    b.count[i] = static_cast<int>(finite.count());
    if (b.count[i] == 0) continue;
    b.mean[i] = finite.select(Z.col(i).array(), 0.0).sum() / b.count[i];
    tested += b.count[i] >= kMinRowValues;
  }
  // The standard error comes from the row's own scatter, not from S: the bias test stays
  // valid when the NIS test fails (a wrong R), and reads the mean against the noise it has.
  DiagnosticTest test;
  test.name = "bias_rows";
  test.accept_low = kNan;
  test.level = level;
  test.p_value = 1.0;
  double worst_ratio = -1.0;
  int worst = -1;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (b.count[i] < kMinRowValues) continue;
    const Eigen::Array<bool, Eigen::Dynamic, 1> finite = Z.col(i).array().isFinite();
    const double ss = finite.select((Z.col(i).array() - b.mean[i]).square(), 0.0).sum();
    const double n_effective = effective_count(Z.col(i), b.mean[i], b.count[i]);
    const double dof = n_effective - 1.0;
    b.standard_error[i] = std::sqrt(ss / (b.count[i] - 1.0) / n_effective);
    b.t[i] = b.standard_error[i] > 0.0 ? b.mean[i] / b.standard_error[i] : 0.0;
    b.t_threshold[i] = student_t_two_sided_quantile(level / tested, dof);
    if (std::fabs(b.t[i]) > b.t_threshold[i]) b.flagged_rows.push_back(static_cast<int>(i));
    const double ratio = std::fabs(b.t[i]) / b.t_threshold[i];
    if (ratio > worst_ratio) {
      worst_ratio = ratio;
      worst = static_cast<int>(i);
      test.statistic = std::fabs(b.t[i]);
      test.accept_high = b.t_threshold[i];
      test.p_value = student_t_two_sided_tail(b.t[i], dof);
    }
  }
  test.passed = b.flagged_rows.empty();
  test.detail = format("%.0f of %.0f rows with a mean innovation beyond their Bonferroni bound",
                       static_cast<double>(b.flagged_rows.size()), tested) +
                (worst >= 0 ? "; largest |t| " + format("%.3g", test.statistic) + " at " + row_name(worst) +
                                  format(" (mean %.3g mm, bound |t| %.3g)", 1e3 * b.mean[worst], test.accept_high)
                            : std::string());
  d.verdict.tests.push_back(test);
}

void spatial_pattern(const Eigen::MatrixXd& Z, const Eigen::MatrixX3d& positions, double level,
                     ResidualDiagnostics& d) {
  SpatialPattern& s = d.spatial;
  const Eigen::Index points = positions.rows();
  int seen = 0;
  for (Eigen::Index j = 0; j < points; ++j)
    if (d.bias.count.segment<3>(3 * j).maxCoeff() > 0) {
      s.centroid += positions.row(j).transpose();
      ++seen;
    }
  if (seen) s.centroid /= seen;
  const RigidFit fit = fit_rigid_motion(positions, s.centroid, d.bias.mean);
  s.translation = fit.translation;
  s.rotation = fit.rotation;
  s.mean_field = as_points(d.bias.mean);
  s.rigid_field = as_points(fit.rigid);
  s.deformation_field = as_points(fit.remainder);
  s.total_rms = finite_rms(d.bias.mean);
  s.rigid_rms = finite_rms(fit.rigid);
  s.deformation_rms = finite_rms(fit.remainder);
  s.rigid_share = s.total_rms > 0.0 ? (s.rigid_rms * s.rigid_rms) / (s.total_rms * s.total_rms) : 0.0;

  // The rigid components step by step: their mean over the steps is the fit of the mean field
  // (the fit is linear) when no row is missing, and their scatter gives its standard error.
  const Eigen::Index N = Z.rows();
  const Eigen::MatrixXd A = rigid_motion_basis(positions, s.centroid);
  const bool all_placed = A.allFinite();   // false when a point has no position (never observed)
  const Eigen::MatrixXd full_solve =
      all_placed ? Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(A).pseudoInverse() : Eigen::MatrixXd();
  Eigen::MatrixXd motion(N, 6);
  for (Eigen::Index t = 0; t < N; ++t) {
    const Eigen::VectorXd z = Z.row(t).transpose();
    if (all_placed && z.allFinite())
      motion.row(t) = (full_solve * z).transpose();
    else {
      const RigidFit step = fit_rigid_motion(positions, s.centroid, z);
      motion.row(t) << step.translation.transpose(), step.rotation.transpose();
    }
  }
  const Eigen::RowVectorXd mean = motion.colwise().mean();
  const Eigen::RowVectorXd sd =
      ((motion.rowwise() - mean).colwise().squaredNorm() / static_cast<double>(N - 1)).cwiseSqrt();
  // Each component's standard error from its effective number of independent steps (as the
  // bias rows'); the bound takes the smallest, the most conservative degrees of freedom.
  double least_effective = static_cast<double>(N);
  for (int c = 0; c < 6; ++c) {
    const double n_effective = effective_count(motion.col(c), mean[c], static_cast<double>(N));
    least_effective = std::min(least_effective, n_effective);
    s.component_t[c] = sd[c] > 0.0 ? mean[c] / (sd[c] / std::sqrt(n_effective)) : 0.0;
  }
  s.component_t_threshold = student_t_two_sided_quantile(level / 6.0, least_effective - 1.0);
  s.least_effective_steps = least_effective;

  DiagnosticTest test;
  test.name = "rigid_bias";
  Eigen::Index worst = 0;
  test.statistic = s.component_t.cwiseAbs().maxCoeff(&worst);
  test.accept_low = kNan;
  test.accept_high = s.component_t_threshold;
  test.p_value = student_t_two_sided_tail(test.statistic, least_effective - 1.0);
  test.level = level;
  test.passed = test.statistic <= test.accept_high;
  static const char* const names[] = {"translation x", "translation y", "translation z",
                                      "rotation x",    "rotation y",    "rotation z"};
  test.detail = format("mean residual: rigid part %.3g mm RMS (translation %.3g mm, rotation %.3g mrad), "
                       "deformation %.3g mm RMS; ",
                       1e3 * s.rigid_rms, 1e3 * s.translation.norm(), 1e3 * s.rotation.norm(),
                       1e3 * s.deformation_rms) +
                format("largest |t| of a rigid component %.3g (", test.statistic) + names[worst] +
                format("), bound %.3g", test.accept_high);
  d.verdict.tests.push_back(test);
}

}  // namespace

const char* to_string(Consistency consistency) {
  switch (consistency) {
    case Consistency::consistent: return "consistent";
    case Consistency::inconsistent: return "inconsistent";
    case Consistency::too_few_steps: return "too_few_steps";
  }
  return "?";
}

std::vector<std::string> ResidualVerdict::failed() const {
  std::vector<std::string> names;
  for (const DiagnosticTest& test : tests)
    if (!test.passed) names.push_back(test.name);
  return names;
}

Eigen::MatrixX3d mean_observed_positions(const Eigen::MatrixXd& points) {
  Eigen::VectorXd mean = Eigen::VectorXd::Constant(points.cols(), kNan);
  for (Eigen::Index c = 0; c < points.cols(); ++c) {
    const Eigen::Array<bool, Eigen::Dynamic, 1> finite = points.col(c).array().isFinite();
    if (finite.count() > 0) mean[c] = finite.select(points.col(c).array(), 0.0).sum() / static_cast<double>(finite.count());
  }
  return as_points(mean);
}

InnovationSeries innovation_series(const EstimationRun& run) {
  InnovationSeries series;
  const auto N = static_cast<Eigen::Index>(run.steps.size());
  Eigen::Index n = 0;
  for (const EstimationStep& step : run.steps) n = std::max(n, step.innovation.size());
  series.innovation = Eigen::MatrixXd::Constant(N, n, kNan);
  series.innovation_std = Eigen::MatrixXd::Constant(N, n, kNan);
  series.normalised_innovation.resize(N);
  for (Eigen::Index k = 0; k < N; ++k) {
    const EstimationStep& step = run.steps[static_cast<std::size_t>(k)];
    series.steps.push_back(step.step);
    series.times.push_back(step.time);
    if (step.innovation.size() == n) {
      series.innovation.row(k) = step.innovation.transpose();
      series.innovation_std.row(k) = step.innovation_std.transpose();
    }
    series.normalised_innovation[k] = step.normalised_innovation;
    series.observed_rows.push_back(step.observed_rows);
    series.catching_up.push_back(step.catching_up);
  }
  return series;
}

InnovationSeries step_means(const InnovationSeries& series) {
  InnovationSeries means = series;
  const Eigen::Index N = series.innovation.rows();
  means.innovation = Eigen::MatrixXd::Constant(N, 1, kNan);
  means.innovation_std = Eigen::MatrixXd::Constant(N, 1, kNan);
  for (Eigen::Index k = 0; k < N; ++k) {
    double sum = 0.0, variance = 0.0;
    int m = 0;
    for (Eigen::Index i = 0; i < series.innovation.cols(); ++i) {
      const double z = series.innovation(k, i), s = series.innovation_std(k, i);
      if (!std::isfinite(z) || !std::isfinite(s)) continue;
      sum += z;
      variance += s * s;
      ++m;
    }
    if (m == 0) continue;
    means.innovation(k, 0) = sum / m;
    means.innovation_std(k, 0) = std::sqrt(variance) / m;
  }
  return means;
}

ResidualDiagnostics diagnose_residuals(const InnovationSeries& series, const Eigen::MatrixX3d& positions,
                                       const ResidualDiagnosticsOptions& options) {
  const auto N_all = static_cast<Eigen::Index>(series.steps.size());
  const Eigen::Index n = series.innovation.cols();
  if (series.innovation.rows() != N_all || series.innovation_std.rows() != N_all ||
      series.innovation_std.cols() != n || series.normalised_innovation.size() != N_all ||
      static_cast<Eigen::Index>(series.observed_rows.size()) != N_all ||
      (!series.catching_up.empty() && static_cast<Eigen::Index>(series.catching_up.size()) != N_all))
    throw std::invalid_argument("diagnose_residuals: the series' parts have different numbers of steps or rows");
  if (positions.rows() != 0 && 3 * positions.rows() != n)
    throw std::invalid_argument("diagnose_residuals: " + std::to_string(positions.rows()) +
                                " observed points for " + std::to_string(n) + " innovation rows");
  if (!(options.false_alarm > 0.0 && options.false_alarm < 1.0) || options.max_lag < 1)
    throw std::invalid_argument("diagnose_residuals: needs 0 < false_alarm < 1 and max_lag >= 1");

  ResidualDiagnostics d;
  d.burn_in_steps = options.burn_in_steps >= 0
                        ? static_cast<int>(std::min<Eigen::Index>(options.burn_in_steps, N_all))
                        : static_cast<int>(N_all / 10);
  for (Eigen::Index k = d.burn_in_steps; k < N_all; ++k) {
    const auto i = static_cast<std::size_t>(k);
    if (!series.catching_up.empty() && series.catching_up[i])
      ++d.catch_up_steps;
    else if (series.observed_rows[i] > 0 && std::isfinite(series.normalised_innovation[k]))
      d.used.push_back(static_cast<int>(k));
  }
  d.steps_used = static_cast<int>(d.used.size());
  if (!d.used.empty()) d.first_step = series.steps[static_cast<std::size_t>(d.used.front())];
  if (d.steps_used < std::max(options.min_steps, 2)) {
    long long rows = 0;
    for (int k : d.used) rows += series.observed_rows[static_cast<std::size_t>(k)];
    if (d.steps_used == 0 || rows < options.min_rows_of_few_steps) {
      d.verdict.consistency = Consistency::too_few_steps;
      return d;
    }
    d.nis_only = true;
    nis_tests(series, d.used, options.false_alarm / 2.0, d);   // its two tests share the rate
    d.verdict.consistency = d.verdict.failed().empty() ? Consistency::consistent : Consistency::inconsistent;
    return d;
  }

  const Eigen::Index N = d.steps_used;
  Eigen::MatrixXd Z(N, n), X(N, n);   // raw and standardised innovations of the steps used
  for (Eigen::Index t = 0; t < N; ++t) {
    const Eigen::Index k = d.used[static_cast<std::size_t>(t)];
    for (Eigen::Index i = 0; i < n; ++i) {
      const double z = series.innovation(k, i), s = series.innovation_std(k, i);
      const bool valid = std::isfinite(z) && std::isfinite(s) && s > 0.0;
      Z(t, i) = valid ? z : kNan;
      X(t, i) = valid ? z / s : kNan;
    }
  }
  const double level = options.false_alarm / kTestCount;
  nis_tests(series, d.used, level, d);
  whiteness_tests(X, options.max_lag, level, d);
  bias_tests(Z, level, d);
  if (positions.rows() > 0) spatial_pattern(Z, positions, level, d);
  d.verdict.consistency = d.verdict.failed().empty() ? Consistency::consistent : Consistency::inconsistent;
  return d;
}

}  // namespace sigmafem
