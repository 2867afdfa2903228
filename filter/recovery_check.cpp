#include "filter/recovery_check.h"

#include <algorithm>
#include <cmath>

#include "filter/statistical_distributions.h"

namespace sigmafem {

// Every axis is tested with the window's full dof - 1 (a step without the axis is rare).
RecoveryCheck::RecoveryCheck(const RecoveryCheckOptions& options)
    : options_(options),
      threshold_(student_t_two_sided_quantile(options.false_alarm / 3.0, options.window - 1.0)) {}

void RecoveryCheck::update(const Eigen::VectorXd& innovation, const Eigen::VectorXd& innovation_std) {
  std::array<double, 3> sum{0.0, 0.0, 0.0};
  std::array<int, 3> count{0, 0, 0};
  for (Eigen::Index i = 0; i < innovation.size(); ++i) {
    const double z = innovation[i], s = innovation_std[i];
    if (std::isnan(z) || !(s > 0.0)) continue;
    sum[static_cast<std::size_t>(i % 3)] += z / s;
    ++count[static_cast<std::size_t>(i % 3)];
  }
  std::array<double, 3> mean;
  for (std::size_t a = 0; a < 3; ++a) mean[a] = count[a] > 0 ? sum[a] / count[a] : NAN;
  means_.push_back(mean);
  if (static_cast<int>(means_.size()) > options_.window) means_.pop_front();
}

double RecoveryCheck::largest_t() const {
  if (static_cast<int>(means_.size()) < options_.window) return 0.0;
  double largest = 0.0;
  for (std::size_t a = 0; a < 3; ++a) {
    double sum = 0.0, sum2 = 0.0;
    int n = 0;
    for (const std::array<double, 3>& m : means_)
      if (!std::isnan(m[a])) sum += m[a], sum2 += m[a] * m[a], ++n;
    if (n < 3) continue;
    const double mean = sum / n;
    const double variance = std::max(0.0, (sum2 - n * mean * mean) / (n - 1));
    if (!(variance > 0.0)) continue;
    largest = std::max(largest, std::abs(mean) / std::sqrt(variance / n));
  }
  return largest;
}

bool RecoveryCheck::recovered() const {
  return static_cast<int>(means_.size()) >= options_.window && largest_t() <= threshold_;
}

}  // namespace sigmafem
