#include "filter/estimation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "filter/catch_up.h"
#include "filter/noise_scale_history.h"
#include "filter/parameter_drift.h"

namespace sigmafem {
namespace {

// The `window` - 1 kept steps before the one being made belong to a catch-up that began with
// it: the change began inside the window that found it.
void mark_catching_up(EstimationRun& run, std::size_t window) {
  for (std::size_t i = run.steps.size() - std::min(run.steps.size(), window - 1); i < run.steps.size(); ++i)
    if (!run.steps[i].catching_up) {
      run.steps[i].catching_up = true;
      ++run.catch_up_steps;
    }
}

// A cut is measured against the estimate before the change began: the step before the
// `window` that found it (the oldest kept one; `now` when none is kept).
void arm_cut_rule(LigamentCutRule& rule, const EstimationRun& run, const EstimationStep& now, std::size_t window) {
  const EstimationStep& before =
      run.steps.empty() ? now : run.steps[run.steps.size() - std::min(run.steps.size(), window)];
  rule.arm(before.theta, before.log_std);
}

}  // namespace

EstimationRun run_estimation(Ensemble& ensemble, const EstimationOptions& options,
                             const std::vector<double>& times, const Eigen::MatrixX3d& so,
                             const Eigen::MatrixXd& points,
                             const std::function<void(const EstimationStep&)>& on_step,
                             const std::function<void(Eigen::Index row)>& before_step) {
  Roukf filter(options.roukf, ensemble);
  ChangeDetector detector(options.detector);
  ParameterChangeTest change_test(options.change_test);
  // A jump is never opened wider than the prior (the parameter's initial std, log units).
  const Eigen::VectorXd& prior_std = filter.prior_std();
  RecoveryCheck recovery(options.recovery);
  // The first parameters that are log-stiffnesses (the rest are effect parameters).
  const Eigen::Index parameters = options.roukf.initial_theta.size();
  const Eigen::Index stiffnesses =
      options.stiffness_count >= 0 ? std::min<Eigen::Index>(options.stiffness_count, parameters) : parameters;
  LigamentCutRule cut_rule(options.cut, static_cast<int>(stiffnesses));
  ParameterDrift drift(options.change_test, parameters);
  CatchUp catch_up(options.detector.hold_off, options.detector.max_catch_up);
  EstimationRun run;
  const auto W = static_cast<std::size_t>(options.detector.window);
  // The steps kept at least: the longest window that can find a change (the detector's or
  // the change test's), as a change is measured from before its window and its catch-up
  // marks the window's steps.
  std::size_t look_back = W;
  for (int w : options.change_test.windows) look_back = std::max(look_back, static_cast<std::size_t>(w));
  const std::size_t quiet = std::max(W, static_cast<std::size_t>(options.change_test.quiet_steps));
  NoiseScaleHistory noise_history(W, quiet);
  for (Eigen::Index k = 1; k < so.rows(); ++k) {
    const auto start = std::chrono::steady_clock::now();
    EstimationStep step;
    step.step = static_cast<int>(k);
    step.time = times[static_cast<std::size_t>(k)];
    RoukfStep result;
    if (before_step) before_step(k);
    try {
      result = filter.step(so.row(k).transpose(), points.row(k).transpose());
    } catch (const std::runtime_error& e) {
      run.complete = false;
      run.stop_reason = "step " + std::to_string(k) + ": " + e.what();
      break;
    }
    step.log_std = result.theta_covariance.diagonal().cwiseSqrt();
    run.final_theta_covariance = result.theta_covariance;
    step.theta = result.theta;
    step.stiffness = result.theta.array().exp();
    step.stiffness_std = step.stiffness.cwiseProduct(step.log_std);
    step.innovation_rms = result.innovation_rms;
    step.normalised_innovation = result.normalised_innovation;
    step.log_det_innovation_covariance = result.log_det_innovation_covariance;
    step.observed_rows = result.observed_rows;
    step.outliers = static_cast<int>(result.outliers.size());
    run.outliers += step.outliers;
    step.noise_scale = result.noise_scale;
    if (result.noise_scale > 1.0) {
      if (run.noise_scaled_steps++ == 0) run.first_noise_scaled_step = step.step;
      run.max_noise_scale = std::max(run.max_noise_scale, result.noise_scale);
    }
    step.innovation = Eigen::VectorXd::Constant(points.cols(), NAN);
    step.innovation_std = Eigen::VectorXd::Constant(points.cols(), NAN);
    for (std::size_t j = 0; j < result.observed_indices.size(); ++j) {
      const auto row = static_cast<Eigen::Index>(j);
      step.innovation[result.observed_indices[j]] = result.innovation[row];
      step.innovation_std[result.observed_indices[j]] = std::sqrt(result.innovation_variance[row]);
    }
    for (std::size_t s = 0; s < result.ensemble.cg_iterations.size(); ++s)
      step.max_cg_iterations = std::max(step.max_cg_iterations, result.ensemble.cg_iterations[s]);
    step.unconverged_sigma_points = result.ensemble.unconverged_count();
    step.factorisations = result.ensemble.factorisations;
    recovery.update(step.innovation, step.innovation_std);
    // A change is acted on only where the model explained the data before it (NoiseScaleHistory).
    noise_history.record(result.noise_scale > 1.0);
    const bool armed = noise_history.quiet_before_window(W);
    const bool change_test_armed = noise_history.quiet_before_window(quiet);
    const int index = static_cast<int>(k) - 1;   // of this step among the steps made, from 0
    const auto begin_catch_up = [&](std::size_t window) {
      if (!catch_up.begin(index)) return false;
      mark_catching_up(run, window);
      return true;
    };
    step.change_detected = detector.update(result.normalised_innovation, result.observed_rows) && armed;
    if (step.change_detected) {
      filter.inflate(options.detector.inflation_log_std);
      filter.hold_adaptive_noise(options.detector.hold_off);
      ++run.changes_detected;
      if (begin_catch_up(W)) arm_cut_rule(cut_rule, run, step, W);
    }
    std::vector<bool> tested = filter.changeable();
    for (std::size_t j = 0; j < tested.size(); ++j)
      tested[j] = tested[j] && step.log_std[static_cast<Eigen::Index>(j)] <
                                   options.change_test.learned_fraction * prior_std[static_cast<Eigen::Index>(j)];
    const ParameterChange change =
        change_test.update(result.score, result.score_covariance, tested, drift.followed_up(static_cast<double>(k)));
    if (change.fired && change_test_armed && drift.goes_on(change)) {
      Eigen::VectorXd jump = change.jump;
      for (Eigen::Index j = 0; j < jump.size(); ++j) jump[j] = std::clamp(jump[j], -prior_std[j], prior_std[j]);
      drift.record(static_cast<double>(k), jump, change);
      filter.open(jump * jump.transpose());
      step.parameters_changed = true;
      run.parameter_changes.push_back({step.step, change.window, change.statistic, change.threshold, jump, change.follow_up});
      // The state catches up on a found change as on one the NIS detector finds (which may
      // fire later or, for a change the data show slowly, never): its innovations are not
      // evidence about the model meanwhile. Only where the model explained the data before
      // (the detector's last reference): under a model error the change test fires now and
      // then (an undeclared lag on box_diagnose), the innovations never come back to a level
      // that ends a catch-up, and each fit would leave out up to max_catch_up steps of the
      // evidence against it. A follow-up belongs to its change's catch-up.
      const bool began = !change.follow_up && detector.model_explained_reference() &&
                         begin_catch_up(static_cast<std::size_t>(change.window));
      if (began || !cut_rule.armed()) arm_cut_rule(cut_rule, run, step, static_cast<std::size_t>(change.window));
    }
    const Eigen::VectorXd drift_variance = drift.variance(static_cast<double>(k));
    if (drift_variance.maxCoeff() > 0.0) filter.open(drift_variance.asDiagonal());
    if (catch_up.update(index, detector.settled() && recovery.recovered())) {
      step.catching_up = true;
      ++run.catch_up_steps;
    }
    for (int j : cut_rule.update(step.theta, step.log_std)) {
      const double before = cut_rule.stiffness_before(j);
      filter.fix(j, std::log(options.cut.remaining * before));
      run.cuts.push_back({j, step.step, step.time, before, cut_rule.upper_bound(j)});
    }
    // A cut ligament is reported at its remaining stiffness, with the data's upper bound
    // as its uncertainty: +-2 std spans zero to that bound (log k has no zero to be near).
    for (const LigamentCut& cut : run.cuts) {
      step.stiffness[cut.parameter] = std::exp(filter.theta()[cut.parameter]);
      step.stiffness_std[cut.parameter] = 0.5 * cut.upper_bound;
    }
    // While the state catches up, its innovations are not evidence about the constants.
    filter.hold_constants(catch_up.running());
    step.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    run.steps.push_back(step);
    if (!options.keep_all_steps && run.steps.size() > look_back) run.steps.erase(run.steps.begin());
    if (on_step) on_step(step);
    for (Eigen::Index j = 0; j < stiffnesses; ++j) {
      const double k_j = step.stiffness[j];
      if (!(k_j >= options.min_stiffness && k_j <= options.max_stiffness)) {
        std::ostringstream reason;
        reason << "step " << k << ": the estimate of parameter " << j << " is " << k_j
               << " N/m, outside " << options.min_stiffness << ".." << options.max_stiffness
               << " N/m: the filter diverged";
        run.complete = false;
        run.stop_reason = reason.str();
        return run;
      }
    }
  }
  return run;
}

}  // namespace sigmafem
