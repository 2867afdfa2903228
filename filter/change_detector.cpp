#include "filter/change_detector.h"

#include "filter/statistical_distributions.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace sigmafem {
bool ChangeDetector::update(double normalised_innovation, int degrees_of_freedom) {
  if (!options_.enabled || degrees_of_freedom <= 0 || !std::isfinite(normalised_innovation))
    return false;
  nis_.push_back(normalised_innovation);
  dof_.push_back(degrees_of_freedom);
  const auto W = static_cast<std::size_t>(options_.window);
  const std::size_t kept = W * static_cast<std::size_t>(1 + options_.reference_windows);
  while (nis_.size() > kept) {
    nis_.pop_front();
    dof_.pop_front();
  }
  // The tested window is the last W steps; the reference, the steps before them.
  const auto tested = static_cast<std::ptrdiff_t>(nis_.size() - std::min(nis_.size(), W));
  statistic_ = std::accumulate(nis_.begin() + tested, nis_.end(), 0.0);
  tested_dof_ = std::accumulate(dof_.begin() + tested, dof_.end(), 0);
  if (silent_for_ > 0) {
    --silent_for_;
    return false;
  }
  // Tested only with a full reference: a level is not known from fewer steps.
  if (nis_.size() < kept) return false;
  const double reference = std::accumulate(nis_.begin(), nis_.begin() + tested, 0.0);
  const int reference_dof = std::accumulate(dof_.begin(), dof_.begin() + tested, 0);
  const bool model_error = reference_dof > 0 &&
      reference > chi_square_tail_quantile(options_.model_error_false_alarm, reference_dof);
  reference_level_ = model_error ? reference / reference_dof : 1.0;
  tested_ = true;
  threshold_ = model_error ? reference_level_ * tested_dof_ * f_tail_quantile(options_.false_alarm, tested_dof_, reference_dof)
                           : chi_square_tail_quantile(options_.false_alarm, tested_dof_);
  if (!fired_) settle_threshold_per_dof_ = threshold_ / tested_dof_;
  if (statistic_ <= threshold_) return false;
  silent_for_ = options_.hold_off;
  fired_ = true;
  settle_threshold_per_dof_ = threshold_ / tested_dof_;
  nis_.clear();
  dof_.clear();
  return true;
}

}  // namespace sigmafem
