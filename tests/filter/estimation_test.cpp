// run_estimation's bounded history (keep_all_steps false, for unbounded runs): the filter
// runs exactly as with every step kept, the change detection's look-back included (a cut is
// detected, its catch-up marked back over the window, the ligament found cut), and only the
// last `window` steps stay in memory.
#include "filter/estimation.h"

#include <gtest/gtest.h>

#include "generated_data.h"
#include "host/engine/estimation_options.h"
#include "host/ensemble/cpu_ensemble.h"
#include "host/model/model.h"
#include "host/scenario/scenario.h"

namespace sigmafem {
namespace {

TEST(EstimationHistory, KeepingOnlyTheWindowChangesNothingButMemory) {
  // The box pulled five times as fast, so that at step 150 of 300 it is as far as the
  // shipped run's cut at step 750, and its cut moved there: the detector is armed (after 60
  // steps) and fires on it.
  Scenario s = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.json");
  s.time.steps = 300;
  s.control.trajectory.velocity *= 5.0;
  s.events[0].time = 1.5;
  // Noise-free data, a small observation std and a small drift, as in BoxEstimation's
  // ChangeDetectorFiresOnTheCutWithASmallDrift: the innovations after the cut stay large
  // enough for the detector.
  s.observations.noise_std = 0.0;
  const ObservationTable data = test::generated_observations(s);

  // Twice: with the change detector alone (the parameter-change test off, so that the NIS
  // fires and its look-back is exercised), then with both (the parameter-change test fires
  // first and arms the cut rule from its own look-back).
  for (const bool change_test : {false, true}) {
  SCOPED_TRACE(change_test ? "with the parameter-change test" : "the change detector alone");
  auto run = [&](bool keep_all_steps, std::vector<EstimationStep>& seen) {
    EstimationOptions options = estimation_options(s);
    options.change_test.enabled = change_test;
    options.keep_all_steps = keep_all_steps;
    options.roukf.observation_std = 1e-4;
    options.roukf.parameter_drift_log_std = 0.02;
    const int p = static_cast<int>(s.filter->estimate.size());
    CpuEnsemble ensemble(make_model(s), s.filter->estimate, s.observations.nodes, p + 1);
    return run_estimation(ensemble, options, data.times, data.so, data.points,
                          [&](const EstimationStep& step) { seen.push_back(step); });
  };
  std::vector<EstimationStep> seen_all, seen_window;
  const EstimationRun all = run(true, seen_all);
  const EstimationRun window = run(false, seen_window);
  ASSERT_TRUE(all.complete) << all.stop_reason;
  ASSERT_TRUE(window.complete) << window.stop_reason;
  if (change_test) {
    ASSERT_FALSE(all.parameter_changes.empty()) << "the cut must fire the test, or its look-back is not exercised";
    ASSERT_EQ(window.parameter_changes.size(), all.parameter_changes.size());
    for (std::size_t i = 0; i < all.parameter_changes.size(); ++i)
      EXPECT_EQ(window.parameter_changes[i].step, all.parameter_changes[i].step);
  } else {
    ASSERT_GT(all.changes_detected, 0) << "the cut must fire the detector, or the look-back is not exercised";
  }
  ASSERT_EQ(all.cuts.size(), 1u);

  // The longest window of the detector and the change test (a catch-up marks its steps).
  std::size_t W = static_cast<std::size_t>(estimation_options(s).detector.window);
  for (int w : estimation_options(s).change_test.windows) W = std::max(W, static_cast<std::size_t>(w));
  EXPECT_EQ(all.steps.size(), 300u);
  EXPECT_EQ(window.steps.size(), W) << "only the longest window is kept";
  ASSERT_EQ(seen_window.size(), seen_all.size()) << "on_step sees every step either way";
  for (std::size_t k = 0; k < seen_all.size(); ++k) {
    EXPECT_EQ(seen_window[k].theta, seen_all[k].theta) << "step " << seen_all[k].step;
    EXPECT_EQ(seen_window[k].change_detected, seen_all[k].change_detected) << "step " << seen_all[k].step;
  }
  for (std::size_t i = 0; i < W; ++i) {
    const EstimationStep& kept = window.steps[i];
    const EstimationStep& full = all.steps[all.steps.size() - W + i];
    EXPECT_EQ(kept.step, full.step);
    EXPECT_EQ(kept.theta, full.theta);
    EXPECT_EQ(kept.catching_up, full.catching_up);
  }
  EXPECT_EQ(window.changes_detected, all.changes_detected);
  EXPECT_EQ(window.catch_up_steps, all.catch_up_steps);
  ASSERT_EQ(window.cuts.size(), all.cuts.size());
  EXPECT_EQ(window.cuts[0].parameter, all.cuts[0].parameter);
  EXPECT_EQ(window.cuts[0].step, all.cuts[0].step);
  EXPECT_EQ(window.cuts[0].stiffness_before, all.cuts[0].stiffness_before) << "measured against the look-back";
  EXPECT_EQ(window.final_theta_covariance, all.final_theta_covariance);
  }
}

}  // namespace
}  // namespace sigmafem
