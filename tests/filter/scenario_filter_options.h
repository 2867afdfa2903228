// The filter a scenario describes (host/engine/estimation_options.h) with the sigma-point
// set and the observation noise a test chooses. Header-only: tests compile *_test.cpp only.
#pragma once

#include "filter/estimation.h"
#include "host/engine/estimation_options.h"

namespace sigmafem::test {

inline EstimationOptions filter_options(const Scenario& scenario, SigmaPointSet set,
                                        double observation_std) {
  EstimationOptions options = estimation_options(scenario);
  options.roukf.sigma_points = set;
  options.roukf.observation_std = observation_std;
  return options;
}

}  // namespace sigmafem::test
