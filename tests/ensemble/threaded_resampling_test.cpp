// resampled_states_on (host/ensemble/threaded_resampling.h): the re-sampling by blocks of rows
// on threads gives the same bits on any thread count, and the formula's own
// (filter/ensemble.h resampled_states on the whole matrix), which the CPU back end and MPI's
// rank 0 both rely on to give the same estimates.
#include "host/ensemble/threaded_resampling.h"

#include <gtest/gtest.h>

#include <random>

namespace sigmafem {
namespace {

Eigen::MatrixXd random_matrix(Eigen::Index rows, Eigen::Index cols, std::mt19937& random) {
  std::normal_distribution<double> normal;
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index j = 0; j < cols; ++j)
    for (Eigen::Index i = 0; i < rows; ++i) m(i, j) = normal(random);
  return m;
}

TEST(ThreadedResampling, TheSameBitsOnAnyThreadCountAsTheWholeMatrix) {
  std::mt19937 random(19);
  for (const auto& [n, p] : {std::pair<Eigen::Index, Eigen::Index>{3 * 596, 3}, {2 * kResamplingBlockRows + 7, 8},
                             {5 * kResamplingBlockRows, 64}}) {
    const Eigen::Index S = p + 1;
    Recentering r;
    r.alpha = 1.0 / static_cast<double>(S);
    r.directions = random_matrix(p, S, random);
    r.correction = random_matrix(p, 1, random);
    r.factor = random_matrix(p, p, random);
    // States around an organ's position (0.3 m), sigma points a millimetre apart.
    const Eigen::MatrixXd Y = Eigen::MatrixXd::Constant(n, S, 0.3) + 1e-3 * random_matrix(n, S, random);
    const Eigen::MatrixXd whole = resampled_states(Y, r);
    for (int threads : {1, 2, 3}) {
      WorkerPool pool(threads);
      const Eigen::MatrixXd blocked = resampled_states_on(pool, Y, r);
      EXPECT_TRUE(blocked == whole) << "n = " << n << ", p = " << p << ", " << threads << " threads: largest difference "
                                    << (blocked - whole).cwiseAbs().maxCoeff();
    }
  }
}

}  // namespace
}  // namespace sigmafem
