#include "host/engine/estimation_options.h"

#include <cmath>

namespace sigmafem {

EstimationOptions estimation_options(const Scenario& scenario) {
  const FilterSpec& spec = *scenario.filter;
  EstimationOptions options;
  options.roukf.sigma_points = parse_sigma_point_set(spec.sigma_points);
  // Ligaments' log-stiffness, then their springs', then regions' log Young's modulus
  // (Scenario::parameter_names).
  std::vector<double> prior(spec.initial_stiffness);
  for (std::size_t i = 0; i < spec.estimate_springs.size(); ++i)
    prior.insert(prior.end(), scenario.ligaments[static_cast<std::size_t>(spec.estimate_springs[i])].nodes.size(),
                 spec.initial_spring_stiffness[i]);
  // Only the stiffnesses are checked against the stiffness range.
  options.stiffness_count = static_cast<int>(prior.size());
  prior.insert(prior.end(), spec.initial_young_modulus.begin(), spec.initial_young_modulus.end());
  options.roukf.initial_theta.resize(static_cast<Eigen::Index>(prior.size()));
  for (std::size_t j = 0; j < prior.size(); ++j) options.roukf.initial_theta[static_cast<Eigen::Index>(j)] = std::log(prior[j]);
  options.roukf.initial_log_std = spec.initial_log_std;
  options.roukf.parameter_drift_log_std = spec.parameter_drift_log_std;
  options.roukf.observation_std = spec.observation_std;
  const ChangeDetectionSpec& detection = spec.change_detection;
  if (detection.enabled) options.detector.enabled = *detection.enabled;
  if (detection.window) options.detector.window = *detection.window;
  if (detection.false_alarm) options.detector.false_alarm = *detection.false_alarm;
  if (detection.hold_off) options.detector.hold_off = *detection.hold_off;
  if (detection.inflation_log_std) options.detector.inflation_log_std = *detection.inflation_log_std;
  if (detection.max_catch_up) options.detector.max_catch_up = *detection.max_catch_up;
  const OutlierGateSpec& gate = spec.outlier_gate;
  if (gate.enabled) options.roukf.outlier_gate.enabled = *gate.enabled;
  if (gate.false_alarm) options.roukf.outlier_gate.false_alarm = *gate.false_alarm;
  if (gate.max_share) options.roukf.outlier_gate.max_share = *gate.max_share;
  const AdaptiveNoiseSpec& adaptive = spec.adaptive_noise;
  if (adaptive.enabled) options.roukf.adaptive_noise.enabled = *adaptive.enabled;
  if (adaptive.window) options.roukf.adaptive_noise.window = *adaptive.window;
  if (adaptive.false_alarm) options.roukf.adaptive_noise.false_alarm = *adaptive.false_alarm;
  return options;
}

}  // namespace sigmafem
