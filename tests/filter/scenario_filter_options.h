// The ROUKF options a scenario's filter block asks for, as the tests that run whole
// estimations need them (the command line builds its own in host/cli/estimation_job.cpp,
// with the change-detection settings too). Header-only: tests compile *_test.cpp files only.
#pragma once

#include <cmath>

#include "filter/estimation.h"
#include "host/scenario/scenario.h"

namespace sigmafem::test {

inline EstimationOptions filter_options(const Scenario& scenario, SigmaPointSet set,
                                        double observation_std) {
  const FilterSpec& spec = *scenario.filter;
  EstimationOptions options;
  options.roukf.sigma_points = set;
  options.roukf.initial_theta.resize(static_cast<Eigen::Index>(spec.estimate.size()));
  for (std::size_t j = 0; j < spec.estimate.size(); ++j)
    options.roukf.initial_theta[static_cast<Eigen::Index>(j)] = std::log(spec.initial_stiffness[j]);
  options.roukf.initial_log_std = spec.initial_log_std;
  options.roukf.parameter_drift_log_std = spec.parameter_drift_log_std;
  options.roukf.observation_std = observation_std;
  return options;
}

}  // namespace sigmafem::test
