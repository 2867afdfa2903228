// The filter settings a scenario's `filter` block asks for (docs/FORMATS.md), as the ROUKF
// and the change detector take them: one mapping for the command line, the tests and the
// benchmarks, so that they all run the filter the scenario describes.
#pragma once

#include "filter/estimation.h"
#include "host/scenario/scenario.h"

namespace sigmafem {

// The scenario's sigma-point set, prior (theta = log of the initial stiffnesses), drift,
// observation noise and change-detection settings. The scenario must have a filter block.
EstimationOptions estimation_options(const Scenario& scenario);

}  // namespace sigmafem
