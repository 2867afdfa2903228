#include "filter/outlier_gate.h"

#include <cstddef>

#include "filter/statistical_distributions.h"

namespace sigmafem {

std::vector<int> gate_outliers(const OutlierGateOptions& options, const std::vector<int>& rows,
                               const Eigen::VectorXd& innovation, const Eigen::VectorXd& variance,
                               int rows_per_point) {
  std::vector<int> outliers;
  if (!options.enabled) return outliers;
  int points = 0;
  const int per_point = rows_per_point;
  std::vector<double> threshold_of;   // by rows observed; -1: not computed yet
  // The rows of one point are consecutive in `rows` (increasing data rows).
  for (std::size_t begin = 0; begin < rows.size();) {
    std::size_t end = begin;
    double d2 = 0.0;
    while (end < rows.size() && rows[end] / per_point == rows[begin] / per_point) {
      const Eigen::Index i = static_cast<Eigen::Index>(end);
      d2 += innovation[i] * innovation[i] / variance[i];
      ++end;
    }
    ++points;
    // The quantile for this many rows, computed once per call (a cloud has a thousand
    // one-row points a step; the quantile is an iterative inverse).
    const std::size_t dof = end - begin;
    if (threshold_of.size() <= dof) threshold_of.resize(dof + 1, -1.0);
    if (threshold_of[dof] < 0.0) threshold_of[dof] = chi_square_tail_quantile(options.false_alarm, static_cast<double>(dof));
    const double threshold = threshold_of[dof];
    if (!(d2 <= threshold)) outliers.push_back(rows[begin] / per_point);   // NaN fails too
    begin = end;
  }
  if (static_cast<double>(outliers.size()) > options.max_share * points) outliers.clear();
  return outliers;
}

std::vector<int> gate_sigma_point_innovations(const OutlierGateOptions& options, const std::vector<int>& rows,
                                              const Eigen::MatrixXd& Z, double alpha,
                                              const Eigen::MatrixXd& directions, double observation_variance,
                                              int rows_per_point) {
  if (!options.enabled) return {};
  Eigen::VectorXd variance = Eigen::VectorXd::Constant(Z.rows(), observation_variance);
  if (directions.cols() == Z.cols()) variance += (alpha * Z * directions.transpose()).rowwise().squaredNorm();
  return gate_outliers(options, rows, alpha * Z.rowwise().sum(), variance, rows_per_point);
}

}  // namespace sigmafem
