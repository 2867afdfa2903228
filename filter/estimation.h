// run_estimation: the filter loop over a whole data set. For each row k >= 1 of the data it
// runs one ROUKF step with the SO at so(k) and the measured points y(k), runs the change
// detector on the innovations, and reports the estimate. Row 0 is the rest state the
// ensemble starts from (no step). It stops early, keeping what it has, when the filter
// diverges (non-finite numbers, or a stiffness outside the physical range).
#pragma once

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "filter/change_detector.h"
#include "filter/ensemble.h"
#include "filter/ligament_cut.h"
#include "filter/parameter_change_test.h"
#include "filter/recovery_check.h"
#include "filter/roukf.h"

namespace sigmafem {

struct EstimationOptions {
  RoukfOptions roukf;
  ChangeDetectorOptions detector;
  RecoveryCheckOptions recovery;   // with the detector, ends a catch-up
  LigamentCutOptions cut;          // after a change: which ligament the data show cut
  // Opens P along a jump of the parameters the innovations show (filter/parameter_change_test.h).
  ParameterChangeTestOptions change_test;
  // N/m: below or above this range the filter has diverged. No floor by default: a cut
  // ligament (truth 0.01 N/m) is zero to the data below about 1 N/m and its log-estimate may
  // go on down (a spring of 1e-30 N/m, or exp underflowing to 0, is harmless); measured, the
  // cut ligament of liver.json crossed 1e-6 N/m at steps 1418-1731 of fits that otherwise
  // explained the data (issue 13), which the old floor of 1e-6 reported as divergence. A
  // non-finite estimate, or one above the ceiling, is divergence.
  double min_stiffness = 0.0;
  double max_stiffness = 1e9;
  // The first `stiffness_count` parameters are log-stiffnesses checked against the range
  // above; the rest (effect parameters, host/model/effects.h) are not stiffnesses.
  // -1: all of them.
  int stiffness_count = -1;
  // false: the run keeps only the steps the change detection looks back on (its longest
  // window: the detector's or the parameter-change test's), so
  // that memory stays flat over an unbounded run (a navigation session; the soak run,
  // bench/soak_main.cpp); on_step sees every step. true: every step, for the reports.
  bool keep_all_steps = true;
};

struct EstimationStep {
  int step = 0;
  double time = 0.0;
  Eigen::VectorXd theta;           // theta_hat, all p parameters
  Eigen::VectorXd stiffness;       // exp(theta_hat): the median estimate, N/m (only the
                                   // first stiffness_count rows are stiffnesses)
  Eigen::VectorXd stiffness_std;   // exp(theta_hat) * std(theta): first-order std, N/m
  Eigen::VectorXd log_std;         // std(theta)
  double innovation_rms = 0.0;     // m
  // For the residual diagnostics (filter/residual_diagnostics.h), on all 3m rows of the data
  // (NaN where the row was missing): the innovation z_bar (observed - predicted mean, m) and
  // sqrt(diag(S)), its standard deviation as the filter sees it (m), so z_i / sqrt(S_ii) is
  // N(0, 1) when the filter is consistent.
  Eigen::VectorXd innovation;
  Eigen::VectorXd innovation_std;
  double normalised_innovation = 0.0;
  double log_det_innovation_covariance = 0.0;   // log det S (Roukf)
  // The adaptive observation-noise scale of the step's correction (1: nominal R;
  // filter/adaptive_noise.h).
  double noise_scale = 1.0;
  int observed_rows = 0;
  int outliers = 0;                // points the outlier gate left out (filter/outlier_gate.h)
  bool change_detected = false;
  // The parameter-change test fired at this step and P was opened along the jump it estimated.
  bool parameters_changed = false;
  // The step lies in the catch-up after a detected change: from the first step of the
  // window that found it (the NIS detector's, or the parameter-change test's on a fresh
  // change; whichever fired first) until the innovations are back within the detector's
  // threshold after its hold-off and their mean is back at zero (RecoveryCheck; at most
  // detector.max_catch_up steps). The reduced-order
  // filter corrects the state only along the parameters' sensitivities, so after a cut the
  // state it carries needs time to meet the organ's new motion even with the right parameters
  // (measured on the liver under 9.81 m/s^2 with the true model: mean NIS about 2000 against
  // 36 over the 100 steps after the cut). The residual tests leave these steps out, diagnose
  // compares fits' likelihoods without them (catch_up_union), and the reports say how many.
  bool catching_up = false;
  int max_cg_iterations = 0;       // over the sigma points
  int unconverged_sigma_points = 0;
  int factorisations = 0;          // of CG's preconditioner, in this step's advance
  double seconds = 0.0;            // wall time of the filter step
};

// A ligament the data showed cut (filter/ligament_cut.h): from `step` on its stiffness is
// held at LigamentCutOptions::remaining of what it was before the change.
struct LigamentCut {
  int parameter = 0;              // index into theta (a log-stiffness)
  int step = 0;                   // the data row at which it was found cut
  double time = 0.0;              // s
  double stiffness_before = 0.0;  // N/m, the estimate before the change began
  // N/m: the upper bound the data showed when the rule fired (LigamentCutRule::upper_bound);
  // from then on the ligament's reported std is half of it.
  double upper_bound = 0.0;
};

struct EstimationRun {
  std::vector<EstimationStep> steps;   // one per data row after the first (with
                                       // keep_all_steps false: the last few of them)
  bool complete = true;
  std::string stop_reason;             // why it stopped early ("" when complete)
  int changes_detected = 0;
  int catch_up_steps = 0;              // steps with catching_up
  std::vector<LigamentCut> cuts;
  // The parameter-change test's firings (filter/parameter_change_test.h) and what was opened.
  struct ParameterChangeRecord {
    int step = 0;                  // data row
    int window = 0;                // steps of the window that fired
    double statistic = 0.0, threshold = 0.0;
    Eigen::VectorXd jump;          // nu_hat (log units), as opened
    bool follow_up = false;        // the follow-up test of a recently changed parameter fired
  };
  std::vector<ParameterChangeRecord> parameter_changes;
  // The adaptive observation noise (filter/adaptive_noise.h): the steps whose correction used
  // lambda > 1, the first of them (data row; 0: none) and the largest lambda.
  int noise_scaled_steps = 0;
  int outliers = 0;                    // point-steps the outlier gate left out, summed
  int first_noise_scaled_step = 0;
  double max_noise_scale = 1.0;
  // theta's covariance after the last step (p x p): how the estimates are correlated, e.g.
  // whether an effect's parameter is told apart from the stiffnesses (diagnose's claims).
  Eigen::MatrixXd final_theta_covariance;
};

// `times` (rows), `so` (rows x 3) and `points` (rows x the ensemble's observation count, NaN =
// missing) are the data;
// `on_step` (may be empty) sees every step as it is made, e.g. for a progress line;
// `before_step` (may be empty) is called with the data row before its step, e.g. to hand a
// point-cloud frame to the observation (filter/point_cloud_observation.h).
EstimationRun run_estimation(Ensemble& ensemble, const EstimationOptions& options,
                             const std::vector<double>& times, const Eigen::MatrixX3d& so,
                             const Eigen::MatrixXd& points,
                             const std::function<void(const EstimationStep&)>& on_step,
                             const std::function<void(Eigen::Index row)>& before_step = {});

}  // namespace sigmafem
