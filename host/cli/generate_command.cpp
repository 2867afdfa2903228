// `sigmafem generate SCENARIO --out DIR [--seed N] [--vtk-every K] [--truth-refine N
// [--truth-springs spread|nodes] | --truth-mesh FILE]`: synthetic data.
#include <iostream>
#include <memory>

#include "host/common/input_error.h"
#include "host/cli/backend_options.h"
#include "host/cli/commands.h"
#include "host/cli/option_checks.h"
#include "host/common/physical_limits.h"
#include "host/cli/report.h"
#include "host/generator/generate.h"
#include "host/scenario/scenario.h"

namespace sigmafem::cli {

Action add_generate_command(CLI::App& app) {
  struct Options {
    std::string scenario;
    GenerateOptions generate;
    BackendChoice backend;
    bool quiet = false;
    double noise_std = -1.0;
    std::vector<std::string> inject;
    int truth_refine = 0;
    std::string truth_mesh;
    std::string truth_springs = "spread";
  };
  auto options = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "generate", "Simulate a scenario with its true stiffnesses and events and write "
                  "observations.csv, truth.csv and a VTK time series");
  sub->add_option("scenario", options->scenario, "Scenario JSON file")->required();
  sub->add_option("--out", options->generate.out_dir, "Output folder (created if missing)")
      ->required();
  sub->add_option("--seed", options->generate.seed, "Seed of the observation noise")
      ->check(whole_number())
      ->capture_default_str();
  sub->add_option("--vtk-every", options->generate.vtk_every,
                  "Write a VTK frame every K steps (0: none; default: the scenario's)")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--noise-std", options->noise_std,
                  "Observation noise std in metres (default: the scenario's observations.noise_std)")
      ->check(finite_between(0.0, kMaxNoiseStd));
  sub->add_option("--outliers", options->generate.outliers,
                  "Share of the point-steps reported 1-2 cm from where the point is (random direction "
                  "and length; measured data's outliers), from step 1 on. Recorded in truth.json")
      ->check(finite_between(0.0, 0.5));
  sub->add_option("--dropouts", options->generate.dropouts,
                  "Share of the point-steps left missing (a tracker losing a point), from step 1 on. "
                  "Recorded in truth.json")
      ->check(finite_between(0.0, 0.9));
  sub->add_option("--gap-steps", options->generate.gap_steps,
                  "With --dropouts: tracked points are lost for runs of steps of this mean length (a "
                  "tracker losing a point for a while), the missing share staying --dropouts")
      ->check(finite_between(1.0, 1e6))
      ->type_name("N");
  sub->add_option("--frame-rate", options->generate.frame_rate,
                  "Frames at this rate (Hz) instead of one per step, each taken and stamped at its own time (the "
                  "organ interpolated between steps): a cloud's in pointcloud.csv, tracked points' in the row of "
                  "the step they fall in, with observations.csv's frame_time column (at most one per step). "
                  "Recorded in truth.json")
      ->check(finite_between(1e-3, 1e4))
      ->type_name("HZ");
  sub->add_option("--frame-jitter", options->generate.frame_jitter,
                  "With --frame-rate: each frame taken at its nominal time plus Gaussian jitter of this "
                  "std (s)")
      ->check(finite_between(0.0, 1.0))
      ->type_name("S");
  sub->add_flag("--frames-on-steps", options->generate.frames_on_steps,
                "With --frame-rate: each frame taken at the step nearest its nominal time (no jitter), "
                "to compare with frames at their own times");
  sub->add_option("--inject", options->inject,
                  "Put an effect into the data without declaring it in the scenario, NAME=VALUE "
                  "(repeatable), e.g. gravity=0,-9.81,0, young_scale=1.5, camera_offset=0.5e-3,0,0, "
                  "extra_ligament:REGION=150 (REGION one of the scenario's candidate_regions); "
                  "effects: " + effect_names() + ". Recorded in truth.json")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  sub->add_option("--truth-refine", options->truth_refine,
                  "Simulate the truth on the scenario's mesh refined N more levels (1 to 3), with "
                  "the same node sets: the data then carry a discretisation error the model lacks. "
                  "Observed positions are read at the observed nodes. Recorded in truth.json")
      ->type_name("N");
  sub->add_option("--truth-springs", options->truth_springs,
                  "With --truth-refine: spread each spring (ligaments, the SO's grip) over the refined "
                  "nodes of the attachment its coarse nodes stand for (spread, the default: the same "
                  "attachment at every level), or keep it on the same nodes (nodes: a point load, softer "
                  "with every level)")
      ->check(CLI::IsMember({"spread", "nodes"}))
      ->type_name("spread|nodes");
  sub->add_option("--truth-mesh", options->truth_mesh,
                  "Simulate the truth on another mesh FILE of the organ (scaled and translated as "
                  "the scenario's mesh; selections made again on it, listed nodes matched by "
                  "position); observed positions are interpolated at the observed nodes' rest "
                  "positions. Recorded in truth.json")
      ->type_name("FILE");
  // The truth is the double-precision reference unless the user names another back end.
  options->backend.backend = "cpu";
  add_backend_options(sub, options->backend);
  sub->add_flag("--quiet", options->quiet, "No progress line and no summary");
  return [options, sub]() {
    // Given or not, whatever the value: --truth-refine 0 is an error, not "off".
    if (sub->count("--truth-refine") > 0) options->generate.truth_mesh.refine = options->truth_refine;
    if (sub->count("--truth-mesh") > 0) options->generate.truth_mesh.file = options->truth_mesh;
    if (sub->count("--truth-springs") > 0 && sub->count("--truth-refine") == 0)
      throw InputError("--truth-springs " + options->truth_springs + ": only with --truth-refine (on --truth-mesh the "
                       "node sets are selected again on the other mesh)");
    options->generate.truth_mesh.spread_springs = options->truth_springs == "spread";
    if (options->generate.outliers + options->generate.dropouts > 1.0)
      throw InputError("--outliers " + message_number(options->generate.outliers) + " and --dropouts " +
                       message_number(options->generate.dropouts) +
                       ": shares of the same point-steps, at most 1 together");
    if ((sub->count("--frame-jitter") > 0 || options->generate.frames_on_steps) && sub->count("--frame-rate") == 0)
      throw InputError("--frame-jitter and --frames-on-steps: only with --frame-rate");
    if (options->generate.frames_on_steps && options->generate.frame_jitter > 0.0)
      throw InputError("--frames-on-steps takes frames at the steps, without jitter: leave out --frame-jitter");
    Scenario scenario = load_scenario(options->scenario);
    for (const std::string& text : options->inject) {
      options->generate.inject.push_back(parse_effect_assignment(text, "--inject"));
      const std::string& name = options->generate.inject.back().name;
      if (!effect_region(name).empty() && !scenario.effect_region_problem(name).empty())
        throw InputError("--inject " + text + ": " + scenario.effect_region_problem(name));
    }
    options->generate.backend = options->backend.backend;
    options->generate.device = options->backend.device_options();
    if (options->noise_std >= 0.0) scenario.observations.noise_std = options->noise_std;
    options->generate.progress = !options->quiet;
    const GenerateResult result = generate(scenario, options->generate, std::cerr);
    if (!options->quiet) print_generate_summary(std::cout, scenario, options->generate, result);
    return 0;
  };
}

}  // namespace sigmafem::cli
