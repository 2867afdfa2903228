#include "filter/path_consistency.h"

#include <algorithm>
#include <cmath>

namespace sigmafem {

PathConsistency path_consistency(const std::vector<EstimationStep>& steps, int parameter, int first,
                                 int interval_count) {
  PathConsistency result;
  const int n = static_cast<int>(steps.size());
  first = std::max(0, first);
  const int length = interval_count > 0 ? (n - 1 - first) / interval_count : 0;
  if (length < 1) return result;
  double sum = 0.0;
  for (int a = first; a + length < n; a += length) {
    const int b = a + length;
    const EstimationStep& from = steps[static_cast<std::size_t>(a)];
    const EstimationStep& to = steps[static_cast<std::size_t>(b)];
    const double variance_drop = from.log_std[parameter] * from.log_std[parameter] -
                                 to.log_std[parameter] * to.log_std[parameter];
    if (!(variance_drop > 0.0)) continue;
    const double change = to.theta[parameter] - from.theta[parameter];
    sum += change * change / variance_drop;
    ++result.intervals;
  }
  if (result.intervals > 0) result.ratio = std::sqrt(sum / result.intervals);
  return result;
}

}  // namespace sigmafem
