#include "filter/change_detector.h"

#include <cmath>
#include <numeric>

namespace sigmafem {
namespace {

// The standard normal quantile of probability 1 - tail (Acklam's rational approximation,
// relative error below 1.2e-9 for the tails used here).
double normal_upper_quantile(double tail) {
  const double q = std::sqrt(-2.0 * std::log(tail));
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  const double x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
                   ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  return -x;
}

}  // namespace

double chi_square_upper_quantile(int k, double tail) {
  const double kd = static_cast<double>(k);
  const double z = normal_upper_quantile(tail);
  const double a = 2.0 / (9.0 * kd);
  const double cube = 1.0 - a + z * std::sqrt(a);
  return kd * cube * cube * cube;
}

bool ChangeDetector::update(double normalised_innovation, int degrees_of_freedom) {
  if (!options_.enabled || degrees_of_freedom <= 0 || !std::isfinite(normalised_innovation))
    return false;
  nis_.push_back(normalised_innovation);
  dof_.push_back(degrees_of_freedom);
  while (static_cast<int>(nis_.size()) > options_.window) {
    nis_.pop_front();
    dof_.pop_front();
  }
  statistic_ = std::accumulate(nis_.begin(), nis_.end(), 0.0);
  threshold_ = chi_square_upper_quantile(std::accumulate(dof_.begin(), dof_.end(), 0),
                                         options_.false_alarm);
  if (silent_for_ > 0) {
    --silent_for_;
    return false;
  }
  if (static_cast<int>(nis_.size()) < options_.window || statistic_ <= threshold_) return false;
  silent_for_ = options_.hold_off;
  nis_.clear();
  dof_.clear();
  return true;
}

}  // namespace sigmafem
