// `sigmafem diagnose SCENARIO --data DIR --out DIR [--candidates a,b] [--max-rounds N]`:
// estimate with the declared model, and while the residual is inconsistent, find the
// candidate effect the data lack, add it and estimate again (host/diagnosis/diagnosis.h).
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <sstream>

#include "filter/sigma_points.h"
#include "host/cli/backend_options.h"
#include "host/cli/commands.h"
#include "host/cli/diagnosis_report.h"
#include "host/cli/option_checks.h"
#include "host/common/input_error.h"
#include "host/common/input_file.h"
#include "host/data/point_cloud_table.h"
#include "host/diagnosis/diagnosis.h"
#include "host/engine/choose_backend.h"
#include "host/engine/estimation_options.h"
#include "host/engine/make_ensemble.h"
#include "host/model/model.h"
#include "host/scenario/scenario.h"

namespace sigmafem::cli {
namespace fs = std::filesystem;

Action add_diagnose_command(CLI::App& app) {
  struct Options {
    std::string scenario, data_dir, out_dir;
    std::string candidates;
    int max_rounds = 3;
    double burn_in = 0.2;
    BackendChoice backend;
    std::string sigma_points = "star";
    bool quiet = false;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "diagnose", "Estimate with the declared model; while the residual is inconsistent, score every candidate "
                  "effect (" + effect_names(true) + ") by its likelihood gain, add the best and estimate again. "
                  "Writes report.md, report.json, residual_before.png, residual_after.png and, when explained, "
                  "scenario.json with the effect declared");
  sub->add_option("scenario", options->scenario, "Scenario JSON file (with a filter block)")->required();
  sub->add_option("--data", options->data_dir, "Folder with observations.csv (truth.csv, truth.json optional)")
      ->required();
  sub->add_option("--out", options->out_dir, "Output folder (created if missing)")->required();
  sub->add_option("--candidates", options->candidates,
                  "Comma-separated candidate effects to try (default: all: " + effect_names(true) +
                      "; extra_ligament alone: one candidate per candidate region of the scenario, "
                      "extra_ligament:REGION: that region)");
  sub->add_option("--max-rounds", options->max_rounds, "Effects added at most")
      ->check(CLI::Range(1, 10))
      ->capture_default_str();
  sub->add_option("--burn-in", options->burn_in,
                  "Share of the steps the residual tests leave out at the start while the filter settles")
      ->check(finite_between(0.0, 0.9))
      ->capture_default_str();
  add_backend_options(sub, options->backend);
  sub->add_option("--sigma", options->sigma_points,
                  "Sigma-point set of every fit: star (symmetric, 2p points) or simplex (p + 1 points), or "
                  "scenario for the scenario's filter.sigma_points")
      ->check(CLI::IsMember(std::vector<std::string>{"simplex", "star", "scenario"}))
      ->capture_default_str();
  sub->add_flag("--quiet", options->quiet, "No progress lines and no summary");
  return [options]() {
    const Scenario scenario = load_scenario(options->scenario);
    if (!scenario.filter)
      throw InputError("scenario " + scenario.path + ": filter: missing; diagnose needs a filter block");
    if (!scenario.filter->estimate_regions.empty() || !scenario.filter->estimate_springs.empty())
      throw InputError("scenario " + scenario.path + ": filter." +
                       (scenario.filter->estimate_springs.empty() ? "estimate_young_modulus" : "estimate_springs") +
                       ": diagnose estimates whole ligaments and candidate effects only; use estimate for the "
                       "fields (regions' moduli, ligaments per spring)");
    const fs::path data(options->data_dir);
    const ObservationTable table = read_observations_csv(
        (data / "observations.csv").string(), static_cast<int>(scenario.observations.observed.size()), scenario.time.dt);
    if (table.row_count() < 2)
      throw InputError("observations " + (data / "observations.csv").string() +
                       ": needs at least two rows (the rest state and one step)");
    std::optional<TruthTable> truth;
    truth = read_optional_truth_csv((data / "truth.csv").string(), scenario.truth_names(), table.row_count(), std::cerr);
    DiagnosisReport report;
    report.data_dir = options->data_dir;
    report.out_dir = options->out_dir;
    // truth.json is optional like truth.csv: unusable, it is a warning and left out.
    if (fs::exists(data / "truth.json")) {
      const std::string path = (data / "truth.json").string();
      try {
        const nlohmann::ordered_json t = nlohmann::ordered_json::parse(read_input_file(path, "truth " + path, kMaxJsonBytes));
        report.truth_effects = {{"declared", t.value("declared_effects", nlohmann::ordered_json::array())},
                                {"injected", t.value("injected_effects", nlohmann::ordered_json::array())}};
      } catch (const std::exception& e) {
        std::cerr << "warning: truth " << path << ": " << e.what()
                  << "; it is optional, so the report goes on without the effects in the data\n";
        report.truth_effects = nullptr;
      }
    }
    DiagnoseOptions diagnose_options;
    // A surface cloud (observations.surface_cloud): its frames, observed as `estimate` does.
    std::optional<PointCloudTable> cloud;
    if (scenario.observations.surface_cloud) {
      diagnose_options.surface_cloud_path = (data / "pointcloud.csv").string();
      cloud = read_point_cloud_csv(diagnose_options.surface_cloud_path);
      diagnose_options.surface_cloud = &*cloud;
    }
    diagnose_options.device = options->backend.device_options();
    diagnose_options.max_rounds = options->max_rounds;
    diagnose_options.burn_in_fraction = options->burn_in;
    diagnose_options.sigma_points = options->sigma_points == "scenario"
                                        ? std::nullopt
                                        : std::optional<SigmaPointSet>(parse_sigma_point_set(options->sigma_points));
    // --backend auto decides by the declared model's ensemble (the candidates' are a few
    // sigma points larger).
    const SigmaPointSet set =
        diagnose_options.sigma_points.value_or(estimation_options(scenario).roukf.sigma_points);
    const Model declared = make_model(scenario);
    const BackendDecision backend = resolve_backend(
        options->backend.backend, declared,
        sigma_point_count(set, static_cast<int>(scenario.filter->estimate.size())),
        EstimatedParameters(scenario.filter->estimate));   // ligaments only: diagnose refuses parameter fields (above)
    diagnose_options.backend = report.backend = backend.backend;
    report.backend_reason = backend.reason;
    report.preconditioner = preconditioner_used(backend.backend, diagnose_options.device, declared);
    if (!options->quiet) std::cout << "backend: " << backend.backend << " (" << backend.reason << ")\n" << std::flush;
    std::stringstream names(options->candidates);
    for (std::string name; std::getline(names, name, ',');)
      if (!name.empty()) diagnose_options.candidates.push_back(name);
    diagnose_options.log = options->quiet ? nullptr : &std::cerr;
    if (!options->quiet) std::cerr << "diagnose " << scenario.name << ":\n";
    const Diagnosis diagnosis = diagnose(scenario, table, truth, diagnose_options);
    const nlohmann::ordered_json j = write_diagnosis_report(scenario, diagnosis, diagnose_options, report);
    if (!options->quiet) {
      std::cout << "outcome: " << j["outcome"].get<std::string>() << "\n" << j["conclusion"].get<std::string>() << "\n"
                << "  " << (fs::path(options->out_dir) / "report.md").string() << "\n  "
                << (fs::path(options->out_dir) / "report.json").string() << '\n';
      if (j["files"].contains("scenario")) std::cout << "  " << j["files"]["scenario"].get<std::string>() << '\n';
    }
    return 0;
  };
}

}  // namespace sigmafem::cli
