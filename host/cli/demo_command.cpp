// `sigmafem demo [box|liver|liver_cloud] [--out DIR]`: the main job on a shipped scenario, from a build
// or an installed copy: generate the scenario's synthetic data into <out>/data, estimate the
// ligament stiffnesses from it into <out>/estimate, and print where the plots are.
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>

#include "host/cli/backend_options.h"
#include "host/cli/commands.h"
#include "host/cli/option_checks.h"
#include "host/cli/estimation_job.h"
#include "host/cli/report.h"
#include "host/common/input_error.h"
#include "host/generator/generate.h"
#include "host/scenario/scenario.h"

namespace sigmafem::cli {
namespace fs = std::filesystem;

namespace {

// The shipped scenarios: $SIGMAFEM_SCENARIOS, the source tree the program was built from,
// or the installed share folder, whichever has the file first.
std::string find_shipped_scenario(const std::string& name) {
  std::vector<fs::path> folders;
  if (const char* env = std::getenv("SIGMAFEM_SCENARIOS")) folders.emplace_back(env);
  folders.emplace_back(SIGMAFEM_SOURCE_SCENARIOS);
  folders.emplace_back(SIGMAFEM_INSTALLED_SCENARIOS);
  std::string looked;
  for (const fs::path& folder : folders) {
    const fs::path candidate = folder / (name + ".json");
    if (fs::exists(candidate)) return candidate.string();
    looked += "\n  " + candidate.string();
  }
  throw InputError("demo: scenario '" + name + "' not found; looked in:" + looked +
                   "\n  set SIGMAFEM_SCENARIOS to the folder that holds it");
}

}  // namespace

Action add_demo_command(CLI::App& app) {
  struct Options {
    std::string scenario = "box";
    std::string out_dir;
    std::uint64_t seed = 1;
    BackendChoice backend;
    std::string sigma_points;
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("demo", "Run the main job on a shipped scenario");
  sub->add_option("scenario", options->scenario, "Shipped scenario")
      ->check(CLI::IsMember({"box", "liver", "liver_cloud"}))
      ->capture_default_str();
  sub->add_option("--out", options->out_dir, "Output folder (default: sigmafem-demo/<scenario>)");
  sub->add_option("--seed", options->seed, "Seed of the observation noise")
      ->check(whole_number())
      ->capture_default_str();
  add_backend_options(sub, options->backend);
  sub->add_option("--sigma", options->sigma_points, "Sigma-point set (default: the scenario's)")
      ->check(CLI::IsMember(std::vector<std::string>{"simplex", "star"}));
  return [options]() {
    const Scenario scenario = load_scenario(find_shipped_scenario(options->scenario));
    const fs::path out =
        options->out_dir.empty() ? fs::path("sigmafem-demo") / options->scenario : fs::path(options->out_dir);
    GenerateOptions generate_options;
    generate_options.out_dir = (out / "data").string();
    generate_options.seed = options->seed;
    generate_options.progress = true;
    // The truth stays the double-precision reference unless a back end is named.
    generate_options.backend = options->backend.backend == "auto" ? "cpu" : options->backend.backend;
    generate_options.device = options->backend.device_options();
    std::cout << "sigmafem demo: scenario " << scenario.path << "\n1. synthetic data\n";
    const GenerateResult result = generate(scenario, generate_options, std::cerr);
    print_generate_summary(std::cout, scenario, generate_options, result);

    std::cout << "2. estimation\n";
    EstimationJob job;
    job.data_dir = generate_options.out_dir;
    job.out_dir = (out / "estimate").string();
    job.backend = options->backend.backend;
    job.device = options->backend.device_options();
    job.sigma_points = options->sigma_points;
    job.out = &std::cout;
    const auto summary = run_estimation_job(scenario, job).value();   // one rank (main)
    print_estimation_summary(std::cout, summary, job.out_dir);
    return summary["complete"].get<bool>() ? 0 : 1;
  };
}

}  // namespace sigmafem::cli
