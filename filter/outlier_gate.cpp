#include "filter/outlier_gate.h"

#include <cstddef>

#include "filter/statistical_distributions.h"

namespace sigmafem {

std::vector<int> gate_outliers(const OutlierGateOptions& options, const std::vector<int>& rows,
                               const Eigen::VectorXd& innovation, const Eigen::VectorXd& variance) {
  std::vector<int> outliers;
  if (!options.enabled) return outliers;
  int points = 0;
  // The rows of one point are consecutive in `rows` (increasing data rows, 3 per point).
  for (std::size_t begin = 0; begin < rows.size();) {
    std::size_t end = begin;
    double d2 = 0.0;
    while (end < rows.size() && rows[end] / 3 == rows[begin] / 3) {
      const Eigen::Index i = static_cast<Eigen::Index>(end);
      d2 += innovation[i] * innovation[i] / variance[i];
      ++end;
    }
    ++points;
    const double threshold =
        chi_square_tail_quantile(options.false_alarm, static_cast<double>(end - begin));
    if (!(d2 <= threshold)) outliers.push_back(rows[begin] / 3);   // NaN fails too
    begin = end;
  }
  if (static_cast<double>(outliers.size()) > options.max_share * points) outliers.clear();
  return outliers;
}

}  // namespace sigmafem
