// The background making's check, shared by the back ends that have it (OpenClFactorTest,
// VulkanDeviceTest; OpenClMultigridTest, VulkanMultigridTest): three runs of the same steps, the
// first waiting for each making of the factor or the multigrid hierarchy, the other two making
// it in the background (host/reference/background_making.h).
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <iostream>

#include "host/common/device_options.h"
#include "tests/refined_liver.h"

namespace sigmafem::test {

// The options that force the background making on a small mesh (the liver's factor is made in
// milliseconds), handed over `lag` steps later (0: waited for); the factor alone, which is
// made more often in few steps than one corrected for the springs.
inline DeviceOptions background_making_options(int lag) {
  DeviceOptions options;
  options.spring_correction = false;
  options.background_making_solves = 0.0;
  options.background_making_steps = lag;
  return options;
}

// One run: the positions at its end, the preconditioner's makings and the CG iterations.
struct MakingRun {
  Eigen::MatrixXd x;
  int makings = 0;
  long iterations = 0;
};

// Handed over at a step fixed when the making began: the two background runs give the same
// bits, and they stay within CG's `tolerance` of the run that waited.
inline void expect_background_making_repeats(const MakingRun& waited, const MakingRun& background,
                                             const MakingRun& again, double tolerance) {
  EXPECT_GE(background.makings, 2) << "no making in the background: the test tests nothing";
  EXPECT_EQ(background.makings, again.makings);
  EXPECT_EQ(background.iterations, again.iterations);
  EXPECT_EQ((background.x - again.x).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_LE((background.x - waited.x).cwiseAbs().maxCoeff(), tolerance);
  std::cout << "makings " << waited.makings << " waited, " << background.makings
            << " in the background; CG iterations " << waited.iterations << " against " << background.iterations
            << "; positions apart by " << (background.x - waited.x).cwiseAbs().maxCoeff() << " m\n";
}

// The multigrid tests' run (OpenClMultigridTest, VulkanMultigridTest): 8 steps of the
// scenario's motion with `theta`, then 8 from its start again with every ligament e times as
// stiff, a system the last hierarchy was not made of: CG takes more iterations, and the rule
// makes it again (with DeviceOptions::multigrid_making_cycles small).
template <class Ensemble>
MakingRun multigrid_making_run(Ensemble& ensemble, const Scenario& scenario, const Eigen::MatrixXd& theta) {
  MakingRun made;
  run_steps(ensemble, scenario, theta, 8, made.iterations);
  made.x = run_steps(ensemble, scenario, Eigen::MatrixXd(theta.array() + 1.0), 8, made.iterations);
  made.makings = ensemble.factorisations();
  return made;
}

}  // namespace sigmafem::test
