// Residual diagnostics (issue 6, item 1): does the model explain the data? After an
// estimation, the innovations z (observed minus predicted positions) of a consistent filter
// are zero-mean, white in time and have the covariance S = H P^- H^T + R the filter
// predicts. Four families of tests look for the ways a missing effect breaks that:
//   NIS        z^T S^-1 z over the steps: is the size of the innovations what S says?
//              (sum over N steps ~ chi^2 with sum m_k dof, the low end allowing a 10%
//              conservative S, which the filter's drift makes; and the share of steps
//              outside their own 95% chi^2 band ~ Binomial(N, 0.05))
//   whiteness  autocorrelation of the standardised innovations z_i / sqrt(S_ii) at lags
//              1..L, averaged over rows, with a one-sided Ljung-Box test (positive
//              correlations: a persisting error; a negative lag 1 is the filter's drift
//              over-correcting, reported, not failed); and per row (each row less its
//              100-step moving average: short-term colour only, slow drifts are the bias
//              tests')
//   bias       mean innovation per observed point and axis, its t-statistic (the standard
//              error from the row's effective number of independent steps: a settling
//              filter's innovations are correlated in time)
//   pattern    the mean innovation field over the observed points split into a rigid part
//              (translation + small rotation about the centroid, least squares) and the rest,
//              with a t-test of the rigid components from per-step fits (effective counts too)
// and a verdict: consistent when every test passes.
//
// False alarms: the verdict runs six tests, each at options.false_alarm / 6 (tests over
// rows or components are Bonferroni-corrected inside that share), so by the union bound a
// consistent filter with Gaussian noise is called inconsistent with probability at most
// options.false_alarm (1% by default), whatever the correlation between the tests; the
// bound rests on chi-square and t approximations that are close, not exact, so far out.
// Measured: 30 inconsistent verdicts in 4000 synthetic consistent runs (0.75%; 450 steps,
// 36 rows, white Gaussian innovations with the stated S; the disabled test
// ResidualDiagnostics.DISABLED_FalseAlarmRateOverManySeeds repeats it).
//
// The input is an InnovationSeries, not the filter: `sigmafem estimate` builds it from its
// run; a later `diagnose` can build it from any run (or from a file) and call the same.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "filter/estimation.h"

namespace sigmafem {

// The innovations of one run, one row per filter step (N steps, 3m observed rows).
struct InnovationSeries {
  std::vector<int> steps;                 // N: data row of each filter step
  std::vector<double> times;              // N: s
  Eigen::MatrixXd innovation;             // N x 3m: z, observed - predicted (m); NaN = missing
  Eigen::MatrixXd innovation_std;         // N x 3m: sqrt(S_ii) (m); NaN = missing
  Eigen::VectorXd normalised_innovation;  // N: z^T S^-1 z with the full S
  std::vector<int> observed_rows;         // N: rows observed at the step (the NIS's dof)
  // N, or empty for none: the step lies in the filter's catch-up after a detected change
  // (EstimationStep::catching_up); the tests leave it out.
  std::vector<bool> catching_up;
};

// The series of a run from run_estimation (steps without any observed row are kept; the
// diagnostics skip them).
InnovationSeries innovation_series(const EstimationRun& run);

// For observations without identity (a surface point cloud: each step's rows are other
// points), the tests that follow a row over the steps have no row to follow. This series has
// one row per step instead: the step's mean innovation over its observed rows (the mean
// signed distance of the cloud from the model's surface), with the std of that mean as if the
// rows were independent; the NIS and its degrees of freedom stay the step's own. Its bias
// test asks whether the cloud lies off the surface on average, its whiteness whether that
// offset persists from step to step; there is no spatial pattern (diagnose_residuals with no
// positions).
InnovationSeries step_means(const InnovationSeries& series);

struct ResidualDiagnosticsOptions {
  int burn_in_steps = -1;      // first steps left out while the filter settles; -1: 10% of the run
  int max_lag = 10;            // whiteness over lags 1..max_lag (at most a fifth of the steps)
  double false_alarm = 0.01;   // bound on P(verdict inconsistent | consistent filter)
  int min_steps = 20;          // fewer steps after the burn-in: too few to judge...
  // ...unless they hold at least this many observed rows together: a few scans of many points
  // (the Truth Cube: three scans of 343 beads) are too few steps to follow a row over time,
  // but their NIS still tests the model. Then only the NIS tests run (nis_only).
  int min_rows_of_few_steps = 300;
};

// One test of the verdict: it passes when `statistic` lies in [accept_low, accept_high]
// (NaN = no bound on that side).
struct DiagnosticTest {
  std::string name;            // nis_mean, nis_above_band, whiteness, whiteness_rows, bias_rows, rigid_bias
  bool passed = true;
  double statistic = 0.0;
  double accept_low = 0.0;
  double accept_high = 0.0;
  double p_value = 0.0;        // of the statistic (for a test over rows: the smallest one,
                               // uncorrected); NaN where not computed
  double level = 0.0;          // the test's share of the false-alarm rate
  std::string detail;          // one line in words
};

enum class Consistency { consistent, inconsistent, too_few_steps };
const char* to_string(Consistency consistency);

struct ResidualVerdict {
  Consistency consistency = Consistency::too_few_steps;
  std::vector<DiagnosticTest> tests;
  std::vector<std::string> failed() const;   // names of the tests that failed
};

struct NisDiagnostics {
  double mean = 0.0;              // mean NIS over the steps used
  double mean_dof = 0.0;          // its expectation: the mean number of observed rows
  double band_low = 0.0;          // two-sided band of the mean NIS at the test's level
  double band_high = 0.0;         //   (sum of NIS ~ chi^2 with sum m_k dof)
  double band95_low = 0.0;        // the same band at 95%, to read the plot by
  double band95_high = 0.0;
  double p_value = 0.0;           // two-sided, of the sum
  int steps_above = 0;            // steps whose NIS is above their own 95% chi^2(m_k) band
  double fraction_above = 0.0;    // expected 0.025
  int max_above = 0;              // the most steps above that the test accepts
  std::vector<double> step_band_low;    // per step used: the 95% chi^2(m_k) band
  std::vector<double> step_band_high;
};

struct WhitenessDiagnostics {
  int max_lag = 0;                      // L
  std::vector<double> autocorrelation;  // lags 1..L: standardised innovations, averaged over rows
  double effective_rows = 0.0;          // n^2 / sum_ij C_ij^2 from the rows' correlation C
  double band = 0.0;                    // 95% band of each averaged lag: 1.96 / sqrt(N effective_rows)
  double ljung_box = 0.0;               // on the averaged autocorrelation's positive lags,
                                        // chi-bar-square of L
  double p_value = 0.0;
  std::vector<double> row_ljung_box;    // per data row (NaN where the row has too few values)
  std::vector<double> row_p_value;
  double row_p_threshold = 0.0;         // Bonferroni: a row below this is flagged
  std::vector<int> flagged_rows;        // data rows (3j + axis) whose innovations are not white
};

struct BiasDiagnostics {
  Eigen::VectorXd mean;                 // per data row: mean innovation (m); NaN if unobserved
  Eigen::VectorXd standard_error;       // its standard error from the row's own scatter (m)
  Eigen::VectorXd t;                    // mean / standard_error
  Eigen::VectorXi count;                // steps the row was observed
  Eigen::VectorXd t_threshold;          // per row: Bonferroni two-sided Student-t bound
  std::vector<int> flagged_rows;        // rows with |t| above their threshold
};

struct SpatialPattern {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  // of the observed points (m)
  Eigen::MatrixX3d mean_field;          // m x 3: mean innovation per point (m)
  Eigen::MatrixX3d rigid_field;         // m x 3: its rigid part t + omega x (p - c)
  Eigen::MatrixX3d deformation_field;   // m x 3: the rest
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();   // t (m)
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();      // omega (rad)
  double total_rms = 0.0;               // over the observed coordinates (m)
  double rigid_rms = 0.0;
  double deformation_rms = 0.0;
  double rigid_share = 0.0;             // rigid_rms^2 / total_rms^2 (the fit is orthogonal)
  // The rigid components (t, omega) fitted step by step: mean / standard error, and the
  // Bonferroni bound over the six components.
  Eigen::Matrix<double, 6, 1> component_t = Eigen::Matrix<double, 6, 1>::Zero();
  double component_t_threshold = 0.0;
  // The fewest effective independent steps of a rigid component (lag-1 autocorrelation rho:
  // N (1 - rho) / (1 + rho)): N / this is how much a persisting error, one that moves every
  // point alike over many steps, slows the averaging of noise away.
  double least_effective_steps = 0.0;
};

struct ResidualDiagnostics {
  int burn_in_steps = 0;      // steps left out at the start
  int steps_used = 0;         // N: steps after the burn-in with at least one observed row,
                              //    outside a catch-up
  int catch_up_steps = 0;     // steps after the burn-in left out as a catch-up after a change
  int first_step = 0;         // data row of the first step used
  std::vector<int> used;      // indices into the series of the steps used
  // Fewer than min_steps steps but at least min_rows_of_few_steps rows: only the NIS tests ran.
  bool nis_only = false;
  NisDiagnostics nis;
  WhitenessDiagnostics whiteness;
  BiasDiagnostics bias;
  SpatialPattern spatial;
  ResidualVerdict verdict;
};

// Where the observed points are on average: the mean over the rows of `points` (rows x 3m,
// NaN = missing) per coordinate, as m x 3 (NaN for a point never observed).
Eigen::MatrixX3d mean_observed_positions(const Eigen::MatrixXd& points);

// `positions` (m x 3): where the observed points are (e.g. their mean observed position),
// for the rigid part of the pattern; none (0 rows): no spatial pattern and no rigid_bias test
// (step_means' series). Throws std::invalid_argument when the sizes disagree.
ResidualDiagnostics diagnose_residuals(const InnovationSeries& series, const Eigen::MatrixX3d& positions,
                                       const ResidualDiagnosticsOptions& options = {});

}  // namespace sigmafem
