// Outlier gate: which observed points of a filter step are outliers, to be left out of that
// step's correction (issue 15, item 3). A tracker or a depth camera now and then reports a
// point centimetres from where it is (a feature mismatched, a reflection); one such point
// enters a Kalman correction with the weight of a good one and pulls every estimate.
//
// The test is the validation gate of target tracking (Bar-Shalom, Li and Kirubarajan,
// "Estimation with Applications to Tracking and Navigation", 2001, 7.3): a point whose
// normalised innovation d^2 = sum over its observed rows of z_i^2 / S_ii exceeds the
// chi-square quantile of probability 1 - false_alarm with as many degrees of freedom as it has
// observed rows is an outlier. S_ii = (H P H^T)_ii + sigma^2 is the innovation variance the
// filter predicts, so under the filter's own model a point is rejected with probability
// false_alarm at most (the rows' correlations are left out: the gate is per point, the
// covariance diagonal; with the default 1e-6 a consistent filter loses about one point in a
// million).
// Many points far off at once are not outliers but a change (a cut, for the change detector)
// or a model error (for the adaptive noise, filter/adaptive_noise.h): when more than
// `max_share` of a step's points fail the gate, none is rejected.
// Off by default (scenario filter.outlier_gate): an unmodelled effect that moves only the
// points near it (an extra ligament) fails the gate at those points alone, and diagnose needs
// to see it.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace sigmafem {

struct OutlierGateOptions {
  bool enabled = false;
  double false_alarm = 1e-6;   // P(a point of a consistent filter is rejected)
  // More of the step's points failing: none is rejected. A half: with 12 points and 5% of
  // them outliers, 3 or 4 at once happen on 1-2% of the steps (a quarter left 11% of the
  // outliers in, BoxEstimation.OutliersAndDropouts...), while a change moves them all.
  double max_share = 0.5;
};

// The points (data row / rows_per_point, Ensemble::rows_per_point) of one step to leave out.
// `rows` are the observed data rows
// (increasing), `innovation` and `variance` the step's z_bar and diag(S) on them.
std::vector<int> gate_outliers(const OutlierGateOptions& options, const std::vector<int>& rows,
                               const Eigen::VectorXd& innovation, const Eigen::VectorXd& variance,
                               int rows_per_point = 3);

// The gate on a step's sigma-point innovations Z (one row per entry of `rows`, one column per
// sigma point) with the filter's nominal variance S_ii = |alpha Z_i I^T|^2 + sigma^2 and mean
// innovation alpha sum Z_i (docs/ROUKF.md): the ROUKF gates its data rows with it, the point-
// cloud observation its points before binning them. `directions` (p x S, I) empty: S_ii =
// sigma^2 (no spread known yet).
std::vector<int> gate_sigma_point_innovations(const OutlierGateOptions& options, const std::vector<int>& rows,
                                              const Eigen::MatrixXd& Z, double alpha,
                                              const Eigen::MatrixXd& directions, double observation_variance,
                                              int rows_per_point);

}  // namespace sigmafem
