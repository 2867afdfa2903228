#include "host/diagnosis/model_form_claim.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "filter/statistical_distributions.h"
#include "host/diagnosis/diagnosis.h"
#include "host/scenario/effect_catalogue.h"

namespace sigmafem {
namespace {

// How far parameter `parameter` at `value` +- `std` (natural units) lies from its absence, in
// stds: of the value for an added quantity, of its log for a factor; where the absence is 0 or
// infinity on a log scale (a lag, an extra ligament's stiffness, d0), of the log's distance to
// nothing finite, so it says whether the value is known to within a factor: value / std.
double distance_from_absence(const EffectParameter& parameter, double value, double std) {
  if (!(std > 0.0)) return 0.0;
  if (!parameter.log) return std::fabs(value - parameter.absent) / std;
  if (parameter.absent > 0.0 && std::isfinite(parameter.absent))
    return std::fabs(std::log(value / parameter.absent)) / (std / value);
  return value / std;
}

// How large `value` of `parameter` is on the effect's full-size scale: its distance from the
// effect's absence in units of the prior's std (gravity 5 m/s^2, an offset 5 mm; the log of a
// factor); for a quantity that is absent at 0 or at infinity on a log scale (a lag, an extra
// ligament's stiffness, d0), its ratio to (or from) the prior's median.
double full_size_share(const EffectParameter& parameter, double value) {
  if (!parameter.log) return std::fabs(value - parameter.absent) / parameter.prior_std;
  if (parameter.absent > 0.0 && std::isfinite(parameter.absent))
    return std::fabs(std::log(value / parameter.absent)) / parameter.prior_std;
  const double median = std::exp(parameter.prior_mean);
  return parameter.absent == 0.0 ? value / median : median / value;
}

// 1 - var(x_i | the stiffnesses) / var(x_i) for coordinate i of the covariance C whose first
// `stiffnesses` coordinates are the log-stiffnesses (a held, cut ligament has no variance: the
// pseudo-inverse leaves it out).
double stiffness_r2(const Eigen::MatrixXd& C, int stiffnesses, int i) {
  const double variance = C(i, i);
  if (!(variance > 0.0) || stiffnesses == 0) return 0.0;
  const Eigen::MatrixXd S = C.topLeftCorner(stiffnesses, stiffnesses);
  const Eigen::VectorXd c = C.block(0, i, stiffnesses, 1);
  const Eigen::VectorXd w = Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>(S).solve(c);
  return std::clamp(c.dot(w) / variance, 0.0, 1.0);
}

}  // namespace

EffectEstimate widened(const EffectEstimate& estimate, const std::vector<EffectEstimate>& later) {
  EffectEstimate out = estimate;
  if (later.empty()) return out;
  out.model_spread.assign(out.value.size(), 0.0);
  for (const EffectEstimate& e : later)
    for (std::size_t i = 0; i < out.model_spread.size() && i < e.value.size(); ++i)
      out.model_spread[i] = std::max(out.model_spread[i], std::fabs(e.value[i] - out.value[i]));
  for (std::size_t i = 0; i < out.std.size(); ++i)
    out.std[i] = std::hypot(out.first_order_std[i] * std::max(1.0, out.path_ratio[i]), out.model_spread[i]);
  return out;
}

std::vector<RunnerUp> runners_up(const std::vector<DiagnosisRound>& rounds) {
  std::vector<RunnerUp> rivals;
  for (std::size_t i = 0; i < rounds.size(); ++i) {
    const DiagnosisRound& r = rounds[i];
    if (r.chosen.empty()) continue;
    RunnerUp rival;
    const CandidateScore& chosen = r.candidates[0];
    rival.chosen_score = chosen.score;
    if (std::isnan(chosen.gain)) rival.ratio = NAN;   // the round's model stopped early
    if (r.candidates.size() > 1 && r.candidates[1].complete && r.candidates[1].score > 0.0) {
      rival.effect = r.candidates[1].effect;
      if (!std::isnan(rival.ratio)) rival.ratio = r.candidates[1].score / chosen.score;
      if (i + 1 < rounds.size())
        for (const CandidateScore& c : rounds[i + 1].candidates)
          if (c.effect == rival.effect && c.complete) rival.after = c.score;
    }
    rivals.push_back(rival);
  }
  return rivals;
}

std::vector<ClaimCheck> check_claims(const std::vector<const ModelFit*>& path, const MisfitShares& shares,
                                     const std::vector<RunnerUp>& runners_up, const ModelFormClaimOptions& options) {
  std::vector<ClaimCheck> checks;
  for (std::size_t j = 1; j < path.size(); ++j) {
    const ModelFit& before = *path[j - 1];
    const ModelFit& fit = *path[j];
    if (fit.estimates.empty()) break;
    const EffectEstimate& estimate = fit.estimates.back();
    const EffectDefinition& definition = *find_effect(estimate.name);
    ClaimCheck check;
    check.effect = estimate.name;
    check.share_of_declared = j - 1 < shares.removed.size() ? shares.removed[j - 1] : NAN;
    const double excess_before = before.residual.nis.mean - before.residual.nis.mean_dof;
    const double excess_after = fit.residual.nis.mean - fit.residual.nis.mean_dof;
    check.share_of_remaining = excess_before > 0.0 ? (excess_before - excess_after) / excess_before : NAN;
    if (j - 1 < runners_up.size()) {
      check.runner_up = runners_up[j - 1].effect;
      check.runner_up_ratio = runners_up[j - 1].ratio;
      check.runner_up_after = runners_up[j - 1].after;
      const double unique = runners_up[j - 1].chosen_score * (1.0 - check.runner_up_ratio) + check.runner_up_after;
      if (unique > 0.0) check.runner_up_unique_ratio = check.runner_up_after / unique;
    }
    const int k = static_cast<int>(estimate.value.size());
    for (int i = 0; i < k; ++i) {
      const double z = distance_from_absence(definition.parameters[static_cast<std::size_t>(i)],
                                             estimate.value[static_cast<std::size_t>(i)],
                                             estimate.std[static_cast<std::size_t>(i)]);
      check.distance += z * z;
    }
    check.distance_bound = chi_square_tail_quantile(options.significance_tail, k);
    for (int i = 0; i < k; ++i)
      check.size += std::pow(full_size_share(definition.parameters[static_cast<std::size_t>(i)],
                                             estimate.value[static_cast<std::size_t>(i)]), 2);
    check.size = std::sqrt(check.size);
    const Eigen::MatrixXd& C = fit.run.final_theta_covariance;
    const int stiffnesses = static_cast<int>(fit.ligaments.size());
    const int first = static_cast<int>(C.rows()) - k;
    if (first >= stiffnesses)
      for (int i = 0; i < k; ++i) check.stiffness_r2 = std::max(check.stiffness_r2, stiffness_r2(C, stiffnesses, first + i));

    if (estimate.name == "young_scale" && before.stiffness.size() == fit.stiffness.size() && estimate.value[0] != 1.0) {
      // Ligaments found cut in either fit are left out: their logs say nothing about a scale.
      auto cut = [](const ModelFit& f, int l) {
        return std::any_of(f.run.cuts.begin(), f.run.cuts.end(), [l](const LigamentCut& c) { return c.parameter == l; });
      };
      // The median: a ligament followed down to near zero after a cut the detector did not
      // see (box.json's middle one, 1.9 -> 0.07 N/m) would swing a mean.
      std::vector<double> changes;
      for (int l = 0; l < static_cast<int>(fit.stiffness.size()); ++l)
        if (!cut(before, l) && !cut(fit, l) && before.stiffness[l] > 0.0 && fit.stiffness[l] > 0.0)
          changes.push_back(std::log(fit.stiffness[l] / before.stiffness[l]));
      if (!changes.empty()) {
        std::sort(changes.begin(), changes.end());
        const std::size_t n = changes.size();
        const double median = n % 2 ? changes[n / 2] : 0.5 * (changes[n / 2 - 1] + changes[n / 2]);
        check.scale_follow = median / std::log(estimate.value[0]);
      }
    }

    if (!fit.run.complete)
      check.reason = "its fit stopped early";
    else if (!(check.share_of_remaining >= options.min_share_of_remaining))
      check.reason = "it took up less than " + std::to_string(static_cast<int>(std::lround(100.0 * options.min_share_of_remaining))) +
                     "% of the misfit left before it";
    else if (std::isnan(check.runner_up_ratio))
      check.reason = "its round's model stopped early, so no rival was compared on fair ground";
    else if (check.runner_up_ratio > options.max_runner_up_ratio &&
             !(check.runner_up_unique_ratio <= options.max_unique_ratio))
      check.reason = check.runner_up + " scored " + std::to_string(static_cast<int>(std::lround(100.0 * check.runner_up_ratio))) +
                     "% of its score" +
                     (std::isnan(check.runner_up_after) ? std::string(" and was not tried beside it")
                                                        : " and still adds beside it " +
                                                              std::to_string(static_cast<int>(std::lround(100.0 * check.runner_up_unique_ratio))) +
                                                              "% of what it adds") +
                     ": the data do not tell the two accounts apart";
    else if (!(check.distance > check.distance_bound))
      check.reason = "its estimate is within 3 std of the effect's absence";
    else if (!(check.size >= options.min_size))
      check.reason = "it is smaller than " + std::to_string(static_cast<int>(std::lround(100.0 * options.min_size))) +
                     "% of the effect's full-size scale (its prior's spread)";
    else if (check.stiffness_r2 > options.max_stiffness_r2)
      check.reason = "the data do not tell it apart from the stiffnesses";
    else if (check.scale_follow > options.max_scale_follow)
      check.reason = "the ligaments moved with it (a scale of every stiffness, which the data do not see)";
    check.claimed = check.reason.empty();
    checks.push_back(check);
    if (!check.claimed) break;
  }
  return checks;
}

}  // namespace sigmafem
