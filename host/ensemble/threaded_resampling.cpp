#include "host/ensemble/threaded_resampling.h"

#include <algorithm>

namespace sigmafem {

Eigen::MatrixXd resampled_states_on(WorkerPool& pool, const Eigen::MatrixXd& Y, const Recentering& recentering) {
  const Eigen::Index n = Y.rows();
  Eigen::MatrixXd result(n, Y.cols());
  const auto blocks = static_cast<int>((n + kResamplingBlockRows - 1) / kResamplingBlockRows);
  pool.run(blocks, [&](int b) {
    const Eigen::Index first = b * kResamplingBlockRows;
    const Eigen::Index rows = std::min(kResamplingBlockRows, n - first);
    result.middleRows(first, rows) = resampled_states(Y.middleRows(first, rows), recentering);
  });
  return result;
}

}  // namespace sigmafem
