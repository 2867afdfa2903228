#include "filter/error_figures.h"

#include <cmath>

namespace sigmafem {
namespace {

bool within_follow_band(double estimate, double truth) {
  const double band = truth < 100.0 ? 5.0 : 0.05 * truth;
  return std::fabs(estimate - truth) <= band;
}

}  // namespace

std::vector<PhaseErrors> error_figures(const std::vector<int>& steps, const Eigen::MatrixXd& estimate,
                                       const Eigen::MatrixXd& std, const Eigen::MatrixXd& truth) {
  std::vector<PhaseErrors> phases;
  const Eigen::Index rows = estimate.rows(), p = estimate.cols();
  if (rows == 0) return phases;
  // Phase boundaries: the rows where the truth differs from the row before.
  std::vector<Eigen::Index> starts = {0};
  for (Eigen::Index k = 1; k < rows; ++k)
    if ((truth.row(k) - truth.row(k - 1)).cwiseAbs().maxCoeff() > 0.0) starts.push_back(k);
  for (std::size_t ph = 0; ph < starts.size(); ++ph) {
    const Eigen::Index begin = starts[ph];
    const Eigen::Index end = ph + 1 < starts.size() ? starts[ph + 1] : rows;   // exclusive
    PhaseErrors phase;
    phase.name = starts.size() == 2 ? (ph == 0 ? "before_cut" : "after_cut")
                                    : "phase_" + std::to_string(ph);
    phase.first_step = steps[static_cast<std::size_t>(begin)];
    phase.last_step = steps[static_cast<std::size_t>(end - 1)];
    const Eigen::Index length = end - begin;
    const Eigen::Index tail = std::max<Eigen::Index>(1, static_cast<Eigen::Index>(std::ceil(0.2 * static_cast<double>(length))));
    double error_sum = 0.0;
    long inside = 0;
    for (Eigen::Index k = end - tail; k < end; ++k) {
      error_sum += (estimate.row(k) - truth.row(k)).cwiseAbs().mean();
      for (Eigen::Index j = 0; j < p; ++j)
        inside += std::fabs(estimate(k, j) - truth(k, j)) <= 2.0 * std(k, j);
    }
    phase.mean_abs_error = error_sum / static_cast<double>(tail);
    phase.coverage = static_cast<double>(inside) / static_cast<double>(tail * p);
    for (Eigen::Index j = 0; j < p; ++j)
      phase.final_error.push_back(std::fabs(estimate(end - 1, j) - truth(end - 1, j)));
    if (ph > 0) {
      // The last row outside the band; following starts after it.
      Eigen::Index last_outside = begin - 1;
      for (Eigen::Index k = begin; k < end; ++k)
        for (Eigen::Index j = 0; j < p; ++j)
          if (!within_follow_band(estimate(k, j), truth(k, j))) last_outside = k;
      phase.steps_to_follow = last_outside + 1 < end ? static_cast<int>(last_outside + 1 - begin) : -1;
    }
    phases.push_back(phase);
  }
  return phases;
}

}  // namespace sigmafem
