#include "host/cli/diagnosis_report.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "host/cli/estimation_report.h"
#include "host/cli/plot.h"
#include "host/cli/residual_report.h"
#include "host/common/atomic_file.h"
#include "host/common/output_set.h"
#include "host/common/input_error.h"
#include "host/diagnosis/diagnosis_conclusion.h"

namespace sigmafem::cli {
namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

namespace {

json optional_number(const std::optional<double>& x) { return x ? finite_number(*x) : json(nullptr); }

std::string model_name(const ModelFit& fit) {
  std::string name = "declared";
  for (const std::string& e : fit.effects) name += " + " + e;
  return name;
}

json estimate_json(const EffectEstimate& e) {
  json j = {{"name", e.name}, {"parameters", e.parameters}, {"units", e.units}, {"value", e.value}, {"std", e.std},
            {"first_order_std", e.first_order_std}, {"path_ratio", e.path_ratio}};
  if (!e.model_spread.empty()) j["model_spread"] = e.model_spread;
  return j;
}

// The failed tests of a fit, each with its one-line detail.
json failed_details(const ModelFit& fit) {
  json failed = json::array();
  for (const DiagnosticTest& test : fit.residual.verdict.tests)
    if (!test.passed) failed.push_back({{"name", test.name}, {"detail", test.detail}});
  return failed;
}

json fit_json(const ModelFit& fit) {
  json stiffness = json::object();
  for (std::size_t j = 0; j < fit.ligaments.size(); ++j) {
    const auto jj = static_cast<Eigen::Index>(j);
    stiffness[fit.ligaments[j]] = {{"stiffness_n_per_m", finite_number(fit.stiffness.size() > jj ? fit.stiffness[jj] : NAN)},
                                   {"std_n_per_m", finite_number(fit.stiffness_std.size() > jj ? fit.stiffness_std[jj] : NAN)}};
  }
  json estimates = json::array();
  for (const EffectEstimate& e : fit.estimates) estimates.push_back(estimate_json(e));
  return {{"model", model_name(fit)},
          {"refined", fit.refined},
          {"effects", estimates},
          {"complete", fit.run.complete},
          {"stop_reason", fit.run.stop_reason},
          {"cuts", cuts_json(fit.run, fit.ligaments)},
          {"verdict", to_string(fit.residual.verdict.consistency)},
          {"failed_tests", failed_details(fit)},
          {"log_likelihood", finite_number(fit.log_likelihood)},
          {"innovation_rms_mm", finite_number(1e3 * fit.innovation_rms)},
          {"stiffness", stiffness},
          {"stiffness_error_n_per_m", optional_number(fit.stiffness_error)},
          {"stiffness_relative_error", optional_number(fit.stiffness_relative_error)}};
}

std::string fixed(double x, int digits) {
  if (!std::isfinite(x)) return "n/a";
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(digits);
  out << x;
  return out.str();
}

std::string estimate_text(const EffectEstimate& e) {
  std::ostringstream out;
  out << "`" << e.name << "` = (";
  for (std::size_t j = 0; j < e.value.size(); ++j) out << (j ? ", " : "") << significant_digits(e.value[j], 4);
  out << ") +- (";
  for (std::size_t j = 0; j < e.std.size(); ++j) out << (j ? ", " : "") << significant_digits(e.std[j], 4);
  out << ")";
  if (!e.units.empty() && !e.units[0].empty()) out << " " << e.units[0];
  if (std::any_of(e.path_ratio.begin(), e.path_ratio.end(), [](double r) { return r > 1.0; })) {
    out << ", std x path ratio (";
    for (std::size_t j = 0; j < e.path_ratio.size(); ++j) out << (j ? ", " : "") << significant_digits(std::max(1.0, e.path_ratio[j]), 4);
    out << ")";
  }
  return out.str();
}

// The scenario with `effects` declared, paths made absolute so that it works from anywhere.
std::string scenario_with_effects(const Scenario& scenario, const std::vector<EffectValue>& discovered) {
  std::ifstream in(scenario.path);
  json root = json::parse(in);
  const fs::path folder = fs::absolute(fs::path(scenario.path)).parent_path();
  root["mesh"]["file"] = (folder / root["mesh"]["file"].get<std::string>()).lexically_normal().string();
  if (root["control"]["trajectory"].contains("file"))
    root["control"]["trajectory"]["file"] =
        (folder / root["control"]["trajectory"]["file"].get<std::string>()).lexically_normal().string();
  json effects = root.contains("effects") ? root["effects"] : json::array();
  for (const EffectValue& effect : discovered)
    effects.push_back({{"name", effect.name},
                       {"value", effect.value.size() == 1 ? json(effect.value[0]) : json(effect.value)}});
  root["effects"] = effects;
  root["description"] = "Discovered by sigmafem diagnose from " + scenario.path + ": " +
                        root.value("description", std::string());
  return root.dump(2) + "\n";
}

}  // namespace

json write_diagnosis_report(const Scenario& scenario, const Diagnosis& d, const DiagnoseOptions& options,
                            const DiagnosisReport& report) {
  // report.json, what a reader opens first, is the set's marker: published last.
  OutputSet output(report.out_dir,
                   {"report.md", "report.json", "residual_before.png", "residual_after.png", "scenario.json"},
                   "report.json");

  json j;
  j["scenario"] = scenario.path;
  j["data"] = report.data_dir;
  j["backend"] = report.backend;
  j["backend_reason"] = report.backend_reason;
  j["preconditioner"] = report.preconditioner;
  const std::string sigma_points =
      options.sigma_points ? to_string(*options.sigma_points) : scenario.filter->sigma_points;
  j["sigma_points"] = sigma_points;
  j["outcome"] = to_string(d.outcome);
  j["conclusion"] = d.conclusion;
  j["penalty"] = "BIC: 0.5 k log N, k the candidate's parameters, N the observed scalars";
  j["candidate_library"] = effect_names(true);
  json discovered = json::array();
  for (const EffectValue& e : d.discovered) discovered.push_back({{"name", e.name}, {"value", e.value}});
  j["discovered_effects"] = discovered;
  j["claimed_estimates"] = json::array();
  const bool claimed = d.outcome == DiagnosisOutcome::explained || d.outcome == DiagnosisOutcome::partly_explained;
  if (claimed)
    for (const EffectEstimate& e : d.after().estimates) j["claimed_estimates"].push_back(estimate_json(e));
  j["truth_effects"] = report.truth_effects;
  json removed = json::array();
  for (std::size_t k = 0; k < d.misfit.removed.size(); ++k)
    removed.push_back({{"effect", d.misfit.effects[k]}, {"share", finite_number(d.misfit.removed[k])}});
  j["misfit"] = {{"declared_excess_nis", finite_number(d.misfit.declared_excess)},
                 {"removed", removed},
                 {"remaining_share", finite_number(d.misfit.remaining)}};
  json claims = json::array();
  for (const ClaimCheck& c : d.claims)
    claims.push_back({{"effect", c.effect},
                      {"share_of_declared", finite_number(c.share_of_declared)},
                      {"share_of_remaining", finite_number(c.share_of_remaining)},
                      {"runner_up", c.runner_up},
                      {"runner_up_ratio", finite_number(c.runner_up_ratio)},
                      {"runner_up_score_after", finite_number(c.runner_up_after)},
                      {"runner_up_unique_ratio", finite_number(c.runner_up_unique_ratio)},
                      {"scale_follow", finite_number(c.scale_follow)},
                      {"distance_from_absence", finite_number(c.distance)},
                      {"distance_bound", finite_number(c.distance_bound)},
                      {"full_size_share", finite_number(c.size)},
                      {"stiffness_r2", finite_number(c.stiffness_r2)},
                      {"claimed", c.claimed},
                      {"reason", c.reason}});
  j["claim_checks"] = claims;
  j["before"] = fit_json(d.before());
  j["after"] = fit_json(d.after());
  json rounds = json::array();
  for (std::size_t r = 0; r < d.rounds.size(); ++r) {
    const DiagnosisRound& round = d.rounds[r];
    json candidates = json::array();
    for (const CandidateScore& c : round.candidates) {
      candidates.push_back({{"effect", c.effect},
                            {"parameters", c.parameters},
                            {"log_likelihood", finite_number(c.log_likelihood)},
                            {"gain", finite_number(c.gain)},
                            {"penalty", finite_number(c.penalty)},
                            {"score", finite_number(c.score)},
                            {"complete", c.complete},
                            {"steps", c.steps},
                            {"compared_steps", c.compared_steps},
                            {"stop_reason", c.stop_reason},
                            {"verdict_with_it", to_string(c.verdict)},
                            {"failed_tests_with_it", failed_details(d.fits[static_cast<std::size_t>(c.fit)])},
                            {"estimate", estimate_json(c.estimate)}});
    }
    const ModelFit& fit = d.fits[static_cast<std::size_t>(round.fit)];
    rounds.push_back({{"round", r + 1},
                      {"model", model_name(fit)},
                      {"verdict", to_string(round.verdict)},
                      {"failed_tests", fit.residual.verdict.failed()},
                      {"log_likelihood", finite_number(fit.log_likelihood)},
                      {"innovation_rms_mm", finite_number(1e3 * fit.innovation_rms)},
                      {"candidates", candidates},
                      {"chosen", round.chosen.empty() ? json(nullptr) : json(round.chosen)}});
  }
  j["rounds"] = rounds;

  // Plots of the residual before and after.
  json files;
  files["report_md"] = output.final_path("report.md");
  if (gnuplot_available()) {
    try {
      plot_residuals(d.before().residual, d.before().series, scenario.name + ", declared model",
                     output.staged("residual_before.png"));
      plot_residuals(d.after().residual, d.after().series, scenario.name + ", " + model_name(d.after()),
                     output.staged("residual_after.png"));
      files["residual_before"] = output.final_path("residual_before.png");
      files["residual_after"] = output.final_path("residual_after.png");
    } catch (const std::exception& e) {
      files["plots_skipped"] = e.what();
    }
  } else {
    files["plots_skipped"] = "gnuplot with PNG output is not installed";
  }
  if (claimed) {
    write_file_atomically(output.staged("scenario.json"), scenario_with_effects(scenario, d.discovered));
    files["scenario"] = output.final_path("scenario.json");
  }
  j["files"] = files;

  std::ostringstream md;
  md << "# sigmafem diagnose: " << scenario.name << "\n\n"
     << "Scenario `" << scenario.path << "`, data `" << report.data_dir << "`, back end " << report.backend
     << ", " << sigma_points << " sigma points.\n\n**Outcome: " << to_string(d.outcome) << ".** " << d.conclusion << "\n\n";
  if (!report.truth_effects.is_null()) md << "Effects in the data (truth.json): `" << report.truth_effects.dump() << "`\n\n";
  md << "## Before and after\n\n| | before (" << model_name(d.before()) << ") | after (" << model_name(d.after())
     << ") |\n|---|---|---|\n"
     << "| residual verdict | " << to_string(d.before().residual.verdict.consistency) << " | "
     << to_string(d.after().residual.verdict.consistency) << " |\n"
     << "| innovation RMS (mm) | " << fixed(1e3 * d.before().innovation_rms, 4) << " | "
     << fixed(1e3 * d.after().innovation_rms, 4) << " |\n"
     << "| log-likelihood | " << fixed(d.before().log_likelihood, 1) << " | " << fixed(d.after().log_likelihood, 1) << " |\n"
     << "| mean NIS (expected: the mean observed rows, " << fixed(d.before().residual.nis.mean_dof, 1) << ") | "
     << fixed(d.before().residual.nis.mean, 2) << " | " << fixed(d.after().residual.nis.mean, 2) << " |\n";
  for (std::size_t k = 0; k < d.misfit.removed.size(); ++k)
    md << "| share of the declared model's excess NIS removed by " << d.misfit.effects[k] << " | | "
       << fixed(100.0 * d.misfit.removed[k], 1) << "% |\n";
  if (d.before().stiffness_error && d.after().stiffness_error)
    md << "| stiffness error, mean over ligaments and the last 20% of steps (N/m) | "
       << fixed(*d.before().stiffness_error, 2) << " | " << fixed(*d.after().stiffness_error, 2) << " |\n";
  if (d.before().stiffness_relative_error && d.after().stiffness_relative_error)
    md << "| stiffness error over the sum of the true stiffnesses | " << fixed(100.0 * *d.before().stiffness_relative_error, 1) << "% | "
       << fixed(100.0 * *d.after().stiffness_relative_error, 1) << "% |\n";
  for (std::size_t l = 0; l < d.before().ligaments.size(); ++l) {
    const auto ll = static_cast<Eigen::Index>(l);
    md << "| " << d.before().ligaments[l] << " (N/m) | " << fixed(d.before().stiffness[ll], 1) << " +- "
       << fixed(d.before().stiffness_std[ll], 1) << " | " << fixed(d.after().stiffness[ll], 1) << " +- "
       << fixed(d.after().stiffness_std[ll], 1) << " |\n";
  }
  for (const EffectEstimate& e : d.after().estimates) md << "| effect | | " << estimate_text(e) << " |\n";
  md << "\n";
  if (files.contains("residual_before"))
    md << "![residual before](residual_before.png)\n\n![residual after](residual_after.png)\n\n";
  if (!d.claims.empty()) {
    md << "## Claims while the residual stays inconsistent\n\nAn effect is claimed when it took up at least "
       << fixed(100.0 * options.claims.min_share_of_remaining, 0)
       << "% of the misfit left before it; no other candidate of its round scored more than "
       << fixed(100.0 * options.claims.max_runner_up_ratio, 0)
       << "% of its score unless, in the model with both, it added at most "
       << fixed(100.0 * options.claims.max_unique_ratio, 0) << "% of what the chosen effect adds; its estimate stands beyond the 3-sigma bound "
          "from the effect's absence in its stated std and is at least "
       << fixed(100.0 * options.claims.min_size, 0) << "% of the effect's full-size scale (its prior's spread); and the data tell it apart from "
          "the stiffnesses (squared multiple correlation at most "
       << fixed(options.claims.max_stiffness_r2, 2) << "; a modulus scale that brought the ligaments' logs along by more than "
       << fixed(100.0 * options.claims.max_scale_follow, 0)
       << "% of its own is not). The first that fails ends the claims (host/diagnosis/model_form_claim.h). A claimed "
          "value's std includes how far it moved in the later fits, not the bias the model error gives every fit alike.\n\n"
       << "| effect | share of the misfit | of what was left | runner-up (score ratio; score beside it, over the chosen one's unique part) "
          "| distance from absence (bound) | size on the full-size scale | r^2 with the stiffnesses | claimed |\n"
          "|---|---|---|---|---|---|---|---|\n";
    for (const ClaimCheck& c : d.claims)
      md << "| " << c.effect << " | " << fixed(100.0 * c.share_of_declared, 1) << "% | "
         << fixed(100.0 * c.share_of_remaining, 1) << "% | "
         << (c.runner_up.empty() ? std::string("none")
                                 : c.runner_up + " (" + fixed(c.runner_up_ratio, 2) + "; " + fixed(c.runner_up_after, 1) + ", " +
                                       fixed(c.runner_up_unique_ratio, 3) + ")")
         << " | " << fixed(c.distance, 1) << " (" << fixed(c.distance_bound, 1) << ") | " << fixed(c.size, 2) << " | "
         << fixed(c.stiffness_r2, 3)
         << (std::isnan(c.scale_follow) ? std::string() : ", ligaments followed " + fixed(c.scale_follow, 2)) << " | "
         << (c.claimed ? std::string("yes") : "no: " + c.reason) << " |\n";
    md << "\n";
  }
  md << "## Rounds\n\nScore = log-likelihood gain of the innovations over every step with the candidate's "
        "parameters estimated, minus the BIC penalty 0.5 k log N. A fit that stopped early is not ranked. An estimate's +- is "
        "its first-order standard deviation, times the path ratio where the estimate moved more than its "
        "covariance allows (docs/ROUKF.md, \"Stated standard deviations\").\n\n";

  for (std::size_t r = 0; r < d.rounds.size(); ++r) {
    const DiagnosisRound& round = d.rounds[r];
    const ModelFit& fit = d.fits[static_cast<std::size_t>(round.fit)];
    md << "### Round " << r + 1 << ": " << model_name(fit) << "\n\nResidual " << to_string(round.verdict);
    const std::vector<std::string> failed = fit.residual.verdict.failed();
    if (!failed.empty()) {
      md << " (failed:";
      for (const std::string& name : failed) md << ' ' << name;
      md << ')';
    }
    md << ", innovation RMS " << fixed(1e3 * fit.innovation_rms, 4) << " mm.\n\n";
    if (round.candidates.empty()) continue;
    md << "| candidate | k | steps | gain | penalty | score | residual with it | estimate |\n"
          "|---|---|---|---|---|---|---|---|\n";
    for (const CandidateScore& c : round.candidates)
      md << "| " << c.effect << " | " << c.parameters << " | " << c.steps
         << (c.complete ? "" : " (stopped: " + c.stop_reason + "; not ranked)") << " | " << fixed(c.gain, 1)
         << " | " << fixed(c.penalty, 1) << " | " << fixed(c.score, 1) << " | " << to_string(c.verdict) << " | "
         << estimate_text(c.estimate) << " |\n";
    if (!round.candidates.empty() && round.candidates[0].complete &&
        round.candidates[0].compared_steps < round.candidates[0].steps)
      md << "\nThe gains are over " << round.candidates[0].compared_steps << " of the "
         << round.candidates[0].steps << " steps: those where a fit was catching up after a detected change "
         << "are left out of every fit's sum.\n";
    if (!fit.run.complete)
      md << "\nThe round's model stopped early (" << fit.run.stop_reason
         << "): the complete candidates are ranked by their own log-likelihood minus the penalty.\n";
    md << "\nChosen: " << (round.chosen.empty() ? std::string("none (no positive score)") : "`" + round.chosen + "`")
       << "\n\n";
  }
  if (files.contains("scenario"))
    md << "The scenario with the discovered effects declared: `scenario.json` (run `sigmafem estimate "
       << output.final_path("scenario.json") << " --data " << report.data_dir << " --out DIR`).\n";
  write_file_atomically(output.staged("report.md"), md.str());
  write_file_atomically(output.staged("report.json"), j.dump(2) + "\n");
  output.publish();
  return j;
}

}  // namespace sigmafem::cli
