// diagnose (issue 6, items 2-3): close the loop from a residual the model does not explain
// to the effect it lacks. Round r:
//   1. fit: run the filter with the declared model plus the effects found so far (their
//      parameters estimated as extra sigma-point dimensions, EffectEnsemble) and test the
//      residual (filter/residual_diagnostics.h);
//   2. if the verdict is consistent, stop: nothing (more) is missing;
//   3. else score every candidate effect not yet in the model: the filter's log-likelihood of
//      the innovations (prediction-error decomposition, sum over steps of
//      -0.5 (z^T S^-1 z + log det S + m log 2 pi), S with the nominal R) with the candidate's
//      parameters estimated, minus the current model's, minus the BIC penalty 0.5 k log N (k
//      the candidate's parameters, N the observed scalars), all on the same steps: every step
//      but those where the round's model or a complete candidate was catching up after a
//      detected change (EstimationStep::catching_up). Only fits that ran over every step
//      are compared (a fit that stopped early is listed with its steps and reason, never ranked
//      by a partial sum); when the round's model itself stopped early, the complete candidates
//      are ranked by their own log-likelihood minus the penalty. The best positive score is
//      added; none: stop.
//   4. refine: run the chosen model once more (always from a complete first pass; the
//      refined pass replaces it only with a log-likelihood at least as high, and never when
//      it stops early) with the prior centred on its estimates, stiffnesses and effects (std: 10 times the posterior std, at least 0.05 in
//      log-stiffness or effect coordinates, at most the first prior). In the
//      first pass the sigma points start a prior std apart (gravity 5 m/s^2), which moves the
//      organ while the filter learns, and without drift it can lock in a small bias (measured
//      on the box when the filter re-sampled positions only: g off by 1%, 4 of its std). The
//      refined pass starts near the answer.
// The outcome: `consistent` (the declared model explains the data; nothing added),
// `explained` (effects were added and the last fit's residual is consistent),
// `partly_explained` (the residual stays inconsistent, but the first effects added took up
// most of the misfit, stand clear of their absence and of the stiffnesses: they are claimed
// with widened stds and what remains is said, host/diagnosis/model_form_claim.h) or
// `unexplained` (the residual stays inconsistent and no effect passes those checks: an effect
// that raised the likelihood is then reported as tried, not as found, with the share of the
// misfit it accounts for: MisfitShares below).
//
// Cost: one filter run per candidate per round, one after another, each on all cores (the CPU
// ensemble's threads); a round with the three candidates on the box costs about four runs.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "filter/estimation.h"
#include "filter/residual_diagnostics.h"
#include "host/common/device_options.h"
#include "host/data/observation_table.h"
#include "host/data/point_cloud_table.h"
#include "host/data/truth_table.h"
#include "host/diagnosis/model_form_claim.h"
#include "host/scenario/effect_catalogue.h"
#include "host/scenario/scenario.h"

namespace sigmafem {

struct DiagnoseOptions {
  std::string backend = "cpu";
  DeviceOptions device;
  int max_rounds = 3;                       // effects added at most
  std::vector<std::string> candidates;      // empty: every candidate of the library
  // The residual tests' options; a burn_in_steps of -1 becomes burn_in_fraction of the steps:
  // 20% rather than the estimate command's 10%, because a candidate's wide prior (gravity:
  // 5 m/s^2 per axis) moves the state more in the first steps than the declared model does.
  ResidualDiagnosticsOptions residual;
  double burn_in_fraction = 0.2;
  // Every fit's sigma-point set. The symmetric star set by default: the filter carries each
  // sigma point's velocity, so a prediction's error from the simplex's skew accumulates over
  // steps, and a weakly observed effect parameter with its wide log prior walks away on it
  // (measured on box_diagnose with a damping (1, 2): the mass factor went to 0.0117 with the
  // simplex, 0.53 +- 0.47 with the star set). Empty: the scenario's filter.sigma_points.
  std::optional<SigmaPointSet> sigma_points = SigmaPointSet::star;
  ModelFormClaimOptions claims;             // when the residual stays inconsistent
  // The data's surface cloud (pointcloud.csv) when the scenario observes one
  // (observations.surface_cloud), and its path for messages; the observation table then
  // holds the times and the SO only. Every fit observes the cloud as `estimate` does
  // (host/engine/surface_cloud_estimation.h), and its residual is judged by its step
  // means (filter/residual_diagnostics.h, step_means).
  const PointCloudTable* surface_cloud = nullptr;
  std::string surface_cloud_path;
  std::ostream* log = nullptr;              // a line per fit, when set
};

struct EffectEstimate {
  std::string name;
  std::vector<std::string> parameters;      // e.g. gx, gy, gz
  std::vector<std::string> units;
  std::vector<double> value;                // natural units (median for a log parameter)
  // The stated standard deviation: the first-order one times max(1, path_ratio), the Birge
  // ratio of the estimate's path (filter/path_consistency.h).
  std::vector<double> std;
  std::vector<double> first_order_std;
  std::vector<double> path_ratio;
  // Under `partly_explained` only (else empty): the model-form spread, the largest move of the
  // estimate between the claimed fit and the later fits along the path (model_form_claim.h).
  std::vector<double> model_spread;
};

// One filter run of the declared model plus `effects`.
struct ModelFit {
  std::vector<std::string> effects;         // estimated effects, in theta order
  EstimationRun run;
  InnovationSeries series;
  ResidualDiagnostics residual;
  double log_likelihood = 0.0;              // over every step with an observed row
  std::vector<double> step_log_likelihood;  // per filter step (0 where nothing was observed)
  long long observed_scalars = 0;           // N: observed rows summed over steps
  int parameter_count = 0;
  double innovation_rms = 0.0;              // m, over the steps the residual tests use
  std::vector<std::string> ligaments;       // the estimated ligaments
  Eigen::VectorXd stiffness, stiffness_std; // final, N/m
  std::vector<EffectEstimate> estimates;    // final, one per effect
  Eigen::VectorXd theta;                    // final: log-stiffnesses, then the effect coordinates
  Eigen::VectorXd theta_std;                // their standard deviations
  bool refined = false;                     // a second pass started at the first pass's estimate
  // Against truth.csv when given, over the last 20% of the steps and the estimated ligaments:
  // the mean of |estimate - truth| (N/m), and its sum over the sum of the truths (a cut
  // ligament's truth is near 0, so a per-ligament ratio would measure nothing but that).
  std::optional<double> stiffness_error;
  std::optional<double> stiffness_relative_error;
};

struct CandidateScore {
  std::string effect;
  int parameters = 0;
  // Over the steps compared: every step of the data but those where the round's model or any
  // complete candidate was catching up after a detected change (EstimationStep::catching_up:
  // there the innovations measure how each filter's state recovers, not the model). Only
  // complete fits are compared, never partial sums over different numbers of steps.
  double log_likelihood = 0.0;
  int compared_steps = 0;
  // Over the model of the round, on the same steps. NaN when the round's model stopped early:
  // the complete candidates are then ranked by log_likelihood - penalty.
  double gain = 0.0;
  double penalty = 0.0;                     // 0.5 k log N
  double score = 0.0;                       // gain - penalty (or log_likelihood - penalty)
  bool complete = true;                     // false: the filter with it stopped (not eligible)
  int steps = 0;                            // filter steps it made
  std::string stop_reason;                  // why it stopped ("" when complete)
  Consistency verdict = Consistency::too_few_steps;
  EffectEstimate estimate;
  int fit = -1;                             // index into Diagnosis::fits
};

struct DiagnosisRound {
  int fit = 0;                              // the model entering the round (Diagnosis::fits)
  Consistency verdict = Consistency::too_few_steps;
  std::vector<CandidateScore> candidates;   // empty when the round's verdict was consistent
  std::string chosen;                       // "" when none was added
};

// How much of the declared model's misfit each effect along the path accounts for. The misfit
// is the excess of the mean NIS over its expectation (the mean number of observed rows), near 0
// for a consistent fit; `removed[j]` is its drop when the j-th effect was added and `remaining`
// what the last fit leaves, both as shares of the declared model's excess (NaN when that
// excess is not positive). On data with a model error no effect of the library removes (a
// truth from a finer mesh) the residual stays inconsistent whatever is added; these shares
// then say whether an effect tried accounted for most of the misfit or for a sliver of it.
struct MisfitShares {
  double declared_excess = 0.0;   // the declared model's mean NIS minus its mean observed rows
  std::vector<std::string> effects;  // the effects added, in the order added
  std::vector<double> removed;    // one per effect added
  double remaining = 0.0;
};

enum class DiagnosisOutcome { consistent, explained, partly_explained, unexplained };
const char* to_string(DiagnosisOutcome outcome);

struct Diagnosis {
  std::vector<ModelFit> fits;               // fits[0]: the declared model; then every fit run
  std::vector<DiagnosisRound> rounds;
  std::vector<int> path;                    // the fits along the chosen effects: declared, +1st, ...
  DiagnosisOutcome outcome = DiagnosisOutcome::unexplained;
  std::vector<EffectValue> discovered;      // the effects claimed, at their final estimates
                                            // (empty unless `explained` or `partly_explained`)
  MisfitShares misfit;                      // along the path
  // When the last fit's residual stays inconsistent: the checks of the effects along the path
  // (host/diagnosis/model_form_claim.h), up to the first that failed.
  std::vector<ClaimCheck> claims;
  // The fit the report calls "after": the path's last, or under `partly_explained` the one
  // with the claimed effects (an index into `path`; -1: the last).
  int after_position = -1;
  std::string conclusion;                   // one paragraph in words
  const ModelFit& before() const { return fits[static_cast<std::size_t>(path.front())]; }
  const ModelFit& after() const {
    return fits[static_cast<std::size_t>(after_position < 0 ? path.back() : path[static_cast<std::size_t>(after_position)])];
  }
};

// One fit: the filter of `scenario` (its declared effects included) with `effects` estimated.
// `start` (optional, size p: the log-stiffnesses, then every effect coordinate): a refined
// pass whose prior is centred on `start` with std `start_std` instead of the scenario's prior
// and N(0, 1).
ModelFit fit_model(const Scenario& scenario, const ObservationTable& data,
                   const std::optional<TruthTable>& truth, const std::vector<std::string>& effects,
                   const DiagnoseOptions& options, const Eigen::VectorXd& start = {},
                   const Eigen::VectorXd& start_std = {});

// Where the refined pass of `first` (a candidate's first pass) starts: its final estimate with
// ten times its std (at least 0.05 per coordinate), except that a ligament it found cut starts
// at its stiffness before the cut, as the refit runs from the first step, before the cut.
struct RefitStart {
  Eigen::VectorXd theta, std;
};
RefitStart refit_start(const ModelFit& first);

// The steps (filter step indices) where any of `fits` that completed was catching up after a
// detected change, and a fit's log-likelihood summed over the other steps: how diagnose
// compares fits on the same steps.
std::vector<bool> catch_up_union(const std::vector<const ModelFit*>& fits);
double log_likelihood_outside(const ModelFit& fit, const std::vector<bool>& left_out);

// The misfit shares (above) of `path`: the declared model's fit first, then one fit per effect
// added.
MisfitShares misfit_shares(const std::vector<const ModelFit*>& path);

// The candidates `names` stand for (empty: every candidate of the library), a regional family
// (extra_ligament) once per candidate region of the scenario. Throws InputError for a name
// outside the library or a region the scenario lacks.
std::vector<std::string> candidate_library(const Scenario& scenario, const std::vector<std::string>& names);

// The rounds above. Throws InputError for a scenario without a filter block, an unknown
// candidate, or data that does not fit the scenario.
Diagnosis diagnose(const Scenario& scenario, const ObservationTable& data,
                   const std::optional<TruthTable>& truth, const DiagnoseOptions& options);

}  // namespace sigmafem
