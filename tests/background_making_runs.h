// The background making's checks, shared by the back ends that have it (OpenClFactorTest,
// VulkanDeviceTest; OpenClMultigridTest, VulkanMultigridTest; host/reference/
// background_making.h): three runs of the same steps, the first waiting for each making of the
// factor or the multigrid hierarchy, the other two making it in the background; and a factor
// made in the background corrected against the springs of the step its making began at.
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

// A change of the sigma points' stiffnesses while a factor is made in the background must not
// reach its spring correction, which is taken against the springs of the step its making
// began at (until stop 63 the hand-over took its own step's: after the change, CG took 991
// iterations over the 40 steps after the hand-over on the liver, OpenCL, against 469 now and
// 392 for the run that waited for the making). `make(lag)` makes the ensemble (the factor in
// the background from any size, handed over `lag` steps later; 0: waited for).
template <class MakeEnsemble>
void expect_the_making_steps_springs(const MakeEnsemble& make, const Scenario& scenario, const Eigen::MatrixXd& theta) {
  const auto so = [&](int step) { return scenario.control.trajectory.position(step * scenario.time.dt, scenario.control.start); };
  // The second making of the run that waits: the background run's begins there too (the two
  // are the same until then).
  int second = 0;
  {
    auto ensemble = make(0);
    ensemble->set_parameters(theta);
    for (int step = 1; step <= 300 && second == 0; ++step)
      if (ensemble->advance(so(step)).factorisations > 0 && step > 1) second = step;
  }
  ASSERT_GT(second, 1) << "no second making in 300 steps: the test tests nothing";
  constexpr int kLag = 3, kWindow = 40;
  // Every stiffness e times larger the step after the making began; the iterations of the
  // kWindow steps after the background run's hand-over.
  const auto iterations_after = [&](int lag) {
    auto ensemble = make(lag);
    ensemble->set_parameters(theta);
    long after = 0;
    for (int step = 1; step <= second + kLag + kWindow; ++step) {
      if (step == second + 1) ensemble->set_parameters(Eigen::MatrixXd(theta.array() + 1.0));
      const StepReport report = ensemble->advance(so(step));
      if (step > second + kLag)
        for (int iterations : report.cg_iterations) after += iterations;
    }
    return after;
  };
  const long waited = iterations_after(0), background = iterations_after(kLag);
  EXPECT_LE(2 * background, 3 * waited) << "a correction against the springs of another step";
  std::cout << "CG iterations over the " << kWindow << " steps after the hand-over: " << background
            << " (waited for: " << waited << ")\n";
}

}  // namespace sigmafem::test
