#include "host/generator/generate.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <random>
#include <vector>

#include "host/common/atomic_file.h"
#include "host/common/machine_memory.h"
#include "host/common/input_error.h"
#include "host/common/output_set.h"
#include "host/common/progress.h"
#include "host/data/csv_format.h"
#include "host/data/observation_table.h"
#include "host/data/point_cloud_table.h"
#include "host/data/truth_table.h"
#include "host/generator/gaussian_noise.h"
#include "host/generator/surface_cloud_sampler.h"
#include "host/generator/vtk_series.h"
#include "host/model/effects.h"
#include "host/model/model.h"
#include <nlohmann/json.hpp>
#include "host/generator/truth_mesh.h"
#include "host/generator/truth_simulation.h"

namespace sigmafem {
namespace fs = std::filesystem;

namespace {

// truth.json's "truth_mesh": which mesh the truth ran on (docs/FORMATS.md).
nlohmann::ordered_json truth_mesh_json(const TruthMesh& truth, const TruthMeshOptions& options) {
  nlohmann::ordered_json j;
  if (options.file) {
    j["file"] = *options.file;
  } else {
    j["refine"] = options.refine.value_or(0);   // levels beyond the scenario's mesh
    if (options.refine) j["springs"] = options.spread_springs ? "spread" : "nodes";
  }
  j["nodes"] = truth.scenario.mesh.node_count();
  j["tetrahedra"] = truth.scenario.mesh.tetrahedron_count();
  j["max_observed_outside_m"] = truth.max_outside_distance;
  return j;
}

// generate keeps the whole observation and truth tables in memory, then their text: refuse a
// run whose tables could not fit before any allocation, naming the field that sets their size.
void check_table_memory(const Scenario& scenario) {
  const double cloud_columns =
      scenario.observations.surface_cloud ? 4.0 * scenario.observations.surface_cloud->points_per_frame : 0.0;
  const double columns = 5.0 + 3.0 * static_cast<double>(scenario.observations.observed.size()) + cloud_columns +
                         static_cast<double>(scenario.ligaments.size());
  constexpr double kBytesPerValue = 8.0 + 24.0;   // the double and its text
  const double needed = (scenario.time.steps + 1.0) * columns * kBytesPerValue;
  const double available = physical_memory_bytes();
  if (available > 0.0 && needed > 0.5 * available)
    throw InputError("scenario " + scenario.path + ": time.steps: " + std::to_string(scenario.time.steps) +
                     " steps of " + std::to_string(scenario.observations.observed.size()) +
                     " observed points need about " + format_number(std::ceil(needed / 1e9)) +
                     " GB for the tables, more than half of this machine's " +
                     format_number(std::floor(available / 1e9)) + " GB; generate fewer steps per run");
}

// When each frame at options.frame_rate is taken (GenerateOptions::frame_rate): within
// (0, steps dt], increasing.
std::vector<double> frame_times_of(const GenerateOptions& options, int steps, double dt, std::uint64_t seed) {
  std::vector<double> times;
  GaussianNoise jitter(seed);
  const double end = steps * dt;
  for (long f = 1;; ++f) {
    const double nominal = static_cast<double>(f) / options.frame_rate;
    if (nominal > end + 1e-12 * dt) break;
    double t = options.frames_on_steps ? std::round(nominal / dt) * dt : nominal + options.frame_jitter * jitter.next();
    t = std::min(t, end);
    if (t <= 0.0 || (!times.empty() && t <= times.back())) continue;   // jittered out of order or range
    times.push_back(t);
  }
  return times;
}

// The start of the message when the truth simulation fails at step k.
std::string diverged_at(int k, double t) {
  return "the truth simulation diverged at step " + std::to_string(k) + " (t = " + format_number(t) + " s): ";
}

}  // namespace

GenerateResult generate(const Scenario& scenario, const GenerateOptions& options,
                        std::ostream& log) {
  const auto start = std::chrono::steady_clock::now();
  // Before the output folder: bad truth mesh options leave nothing behind.
  check_table_memory(scenario);
  if (!(options.frame_rate >= 0.0 && options.frame_jitter >= 0.0))
    throw InputError("generate: the frame rate and the frame jitter must not be negative");
  if (!(options.gap_steps >= 1.0))
    throw InputError("generate: the mean gap length is at least 1 step, found " + format_number(options.gap_steps));
  if (options.gap_steps > 1.0 && scenario.observations.surface_cloud)
    throw InputError("scenario " + scenario.path + ": gaps of several steps are for tracked points; a cloud's points "
                     "have no identity to lose (use --dropouts alone)");
  if (options.frame_rate * scenario.time.dt > 1.0 && !scenario.observations.surface_cloud)
    throw InputError("generate: --frame-rate " + format_number(options.frame_rate) + " Hz is faster than the "
                     "simulation's steps (" + format_number(1.0 / scenario.time.dt) + " Hz); tracked points take "
                     "at most one frame per step");
  const TruthMesh truth_mesh = make_truth_mesh(scenario, options.truth_mesh);
  if (!truth_mesh.ligament_spread.empty() && options.backend != "cpu")
    throw InputError("--truth-refine with --backend " + options.backend +
                     ": the springs spread over the refined mesh give each node its own part of a ligament, which the "
                     "device back ends do not hold; use --backend cpu, or --truth-springs nodes");
  // observations.csv, what estimate reads, is the set's marker: published last.
  OutputSet output(options.out_dir,
                   {"observations.csv", "pointcloud.csv", "truth.csv", "truth.json", scenario.name + ".pvd", "vtk"},
                   "observations.csv");

  Model truth_model = truth_mesh.model();   // declared effects included
  apply_effects(options.inject, truth_model);
  // What a camera adds to every observed position: declared and injected registration errors.
  const Eigen::Vector3d offset = camera_offset(scenario.effects) + camera_offset(options.inject);
  TruthSimulation simulation(std::move(truth_model), options);
  const Model& model = simulation.model();
  const int steps = scenario.time.steps;
  const double dt = scenario.time.dt;
  const ObservedPoints& observed = scenario.observations.observed;
  const int vtk_every = options.vtk_every >= 0 ? options.vtk_every : scenario.output.vtk_every;

  std::vector<std::string> comments = {
      "scenario " + scenario.name, "seed " + std::to_string(options.seed),
      "noise_std " + format_number(scenario.observations.noise_std) + " m",
      "generated by sigmafem " SIGMAFEM_VERSION};
  if (options.outliers > 0.0 || options.dropouts > 0.0)
    comments.push_back("faults: outliers " + format_number(options.outliers) + ", dropouts " +
                       format_number(options.dropouts) + " of the point-steps");
  ObservationTable table;
  table.comments = comments;
  table.so.resize(steps + 1, 3);
  table.points.resize(steps + 1, 3 * static_cast<Eigen::Index>(observed.size()));
  TruthTable truth;
  truth.comments = comments;
  // The ligaments' stiffness (N/m), the springs estimated alone, each region's modulus (Pa).
  truth.names = scenario.truth_names();
  truth.stiffness.resize(steps + 1, static_cast<Eigen::Index>(truth.names.size()));
  GaussianNoise noise(options.seed);
  // The faults' own stream (GenerateOptions::outliers): the noise above stays the same.
  std::mt19937_64 faults(options.seed ^ 0x9e3779b97f4a7c15ULL);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  GaussianNoise direction(options.seed ^ 0x6a09e667f3bcc909ULL);

  // A surface cloud (observations.surface_cloud) instead of tracked points: sampled on the
  // truth mesh's own surface, from a stream of its own.
  std::optional<SurfaceCloudSampler> sampler;
  PointCloudTable cloud;
  std::vector<double> frame_times;   // with a frame rate: when each frame is taken
  std::size_t next_frame = 0;
  if (options.frame_rate > 0.0) frame_times = frame_times_of(options, steps, dt, options.seed ^ 0x3c6ef372fe94f82bULL);
  if (scenario.observations.surface_cloud) {
    const SurfaceCloud& spec = *scenario.observations.surface_cloud;
    sampler.emplace(truth_mesh.scenario.mesh, spec, options.seed ^ 0xbb67ae8584caa73bULL);
    cloud.comments = comments;
    cloud.comments.push_back("surface cloud: " + std::to_string(spec.points_per_frame) +
                             " points per frame before dropouts, coverage " + format_number(spec.coverage) +
                             ", view direction " + format_number(spec.view_direction.x()) + " " +
                             format_number(spec.view_direction.y()) + " " + format_number(spec.view_direction.z()));
  }

  GenerateResult result;
  // One measured point's faults from step 1 on (GenerateOptions::outliers): moved 1-2 cm, or
  // dropped (false). `lost_for`: a tracked point's steps left in its gap (gap_steps > 1).
  std::vector<int> lost_for(observed.size(), 0);
  // Tracked runs of mean (1 - g) / g steps between gaps of mean L: missing share
  // g L / (1 - g + g L) = dropouts.
  const double gap_start =
      options.dropouts / (options.gap_steps * (1.0 - options.dropouts) + options.dropouts);
  auto keep_with_faults = [&](Eigen::Vector3d& point, int* lost) {
    if (options.outliers <= 0.0 && options.dropouts <= 0.0) return true;
    const double draw = uniform(faults);
    bool dropped = draw < options.dropouts;
    double outliers_from = options.dropouts;   // draws in [from, from + outliers): an outlier
    if (lost && options.gap_steps > 1.0) {
      // Gaps: a lost point stays lost; else it is lost now with probability gap_start, for a
      // geometric number of steps of mean gap_steps (this one included).
      if (*lost == 0 && draw < gap_start)
        *lost = 1 + static_cast<int>(std::floor(std::log1p(-uniform(faults)) / std::log1p(-1.0 / options.gap_steps)));
      dropped = *lost > 0;
      if (dropped) --*lost;
      outliers_from = gap_start;
    }
    if (dropped) {
      ++result.dropouts;
      return false;
    }
    if (draw >= outliers_from && draw < outliers_from + options.outliers) {
      Eigen::Vector3d away(direction.next(), direction.next(), direction.next());
      point += away * (0.01 + 0.01 * uniform(faults)) / away.norm();
      ++result.outliers;
    }
    return true;
  };
  // What the camera or tracker reports for a point: the offset and the noise added.
  auto measured = [&](const Eigen::Vector3d& point) {
    Eigen::Vector3d m = point + offset;
    for (int a = 0; a < 3; ++a) m[a] += scenario.observations.noise_std * noise.next();
    return m;
  };
  Eigen::VectorXd positions, previous_positions;
  // One frame of the cloud, of the organ at `at`, taken at time t.
  auto take_frame = [&](double t, const Eigen::VectorXd& at) {
    const Eigen::Matrix3Xd sampled = sampler->sample(at);
    PointCloudFrame frame{t, Eigen::Matrix3Xd(3, sampled.cols())};
    Eigen::Index kept = 0;
    for (Eigen::Index i = 0; i < sampled.cols(); ++i) {
      Eigen::Vector3d point = measured(sampled.col(i));
      if (keep_with_faults(point, nullptr)) frame.points.col(kept++) = point;
    }
    frame.points.conservativeResize(3, kept);
    cloud.frames.push_back(std::move(frame));
  };
  auto record = [&](int k) {
    previous_positions = positions;
    positions = simulation.positions();
    const double t = k * dt;
    table.steps.push_back(k);
    table.times.push_back(t);
    table.so.row(k) = scenario.control.trajectory.position(t, scenario.control.start).transpose();
    // The tracked points of one frame, of the organ at `at`, into row k.
    auto track = [&](const Eigen::VectorXd& at) {
      for (std::size_t p = 0; p < observed.size(); ++p) {
        Eigen::Vector3d point = measured(truth_mesh.observed[p].of(at));
        if (k > 0 && !keep_with_faults(point, &lost_for[p])) point.setConstant(std::nan(""));
        table.points.row(k).segment<3>(static_cast<Eigen::Index>(3 * p)) = point.transpose();
      }
    };
    if (sampler || frame_times.empty() || k == 0) {
      track(positions);
      if (!frame_times.empty() && !sampler) table.frame_times.push_back(0.0);   // the rest state
    } else {
      // Tracked frames at their own times: the one taken in ((k-1) dt, k dt] (of two, the
      // later), of the organ interpolated between the two steps; none: the row is empty.
      table.points.row(k).setConstant(std::nan(""));
      table.frame_times.push_back(std::nan(""));
      for (; next_frame < frame_times.size() && frame_times[next_frame] <= t + 1e-12 * dt; ++next_frame) {
        const double share = (frame_times[next_frame] - (t - dt)) / dt;
        track(previous_positions + share * (positions - previous_positions));
        table.frame_times.back() = frame_times[next_frame];
      }
    }
    if (sampler && k > 0 && options.frame_rate <= 0.0) take_frame(t, positions);   // a frame per step
    // Frames at their own times: those taken in ((k-1) dt, k dt], of the organ interpolated
    // between the two steps.
    for (; sampler && k > 0 && next_frame < frame_times.size() && frame_times[next_frame] <= t + 1e-12 * dt;
         ++next_frame) {
      const double share = (frame_times[next_frame] - (t - dt)) / dt;
      take_frame(frame_times[next_frame], previous_positions + share * (positions - previous_positions));
    }
    truth.steps.push_back(k);
    truth.times.push_back(t);
    for (std::size_t l = 0; l < scenario.ligaments.size(); ++l)
      truth.stiffness(k, static_cast<Eigen::Index>(l)) = simulation.ligament_stiffness()[l];   // declared ones
    auto column = static_cast<Eigen::Index>(scenario.ligaments.size());
    if (scenario.filter)   // each spring the filter estimates on its own: its part of its ligament
      for (int l : scenario.filter->estimate_springs)
        for (std::size_t j = 0; j < scenario.ligaments[static_cast<std::size_t>(l)].nodes.size(); ++j)
          truth.stiffness(k, column++) = model.ligaments[static_cast<std::size_t>(l)].node_part(
              j, simulation.ligament_stiffness()[static_cast<std::size_t>(l)]);
    for (const Region& region : scenario.regions) truth.stiffness(k, column++) = region.young_modulus;
    for (int i = 0; i < model.node_count(); ++i)
      result.max_displacement =
          std::max(result.max_displacement,
                   (positions.segment<3>(3 * i) - model.rest_positions[i]).norm());
  };

  std::unique_ptr<VtkSeries> vtk;
  if (vtk_every > 0)
    vtk = std::make_unique<VtkSeries>(model, truth_mesh.nearest_observed_nodes(), output.staging_folder(), scenario.name);

  // The scenario's ligaments (events applied), then any extra ligament of an effect at the
  // model's stiffness.
  auto stiffness_at = [&](double t) {
    std::vector<double> k = scenario.ligament_stiffness_at(t);
    for (std::size_t l = k.size(); l < model.ligaments.size(); ++l) k.push_back(model.ligaments[l].stiffness);
    return k;
  };
  simulation.set_ligament_stiffness(stiffness_at(0.0));
  record(0);
  if (vtk) vtk->write_frame(0.0, positions);
  Progress progress("generate " + scenario.name + ": step", steps, options.progress);
  for (int k = 1; k <= steps; ++k) {
    const double t = k * dt;
    simulation.set_ligament_stiffness(stiffness_at(t));
    CgResult cg;
    try {
      cg = simulation.step(scenario.control.trajectory.position(t, scenario.control.start));
    } catch (const std::runtime_error& e) {
      throw std::runtime_error(diverged_at(k, t) + e.what());
    }
    // A residual that is not finite is no solve at all: the state would be garbage from here.
    if (!std::isfinite(cg.relative_residual))
      throw std::runtime_error(diverged_at(k, t) + "the solve's residual is not finite (the load or the stiffness "
                               "overflowed, or the system is not positive definite); nothing is written");
    result.cg_iterations += cg.iterations;
    result.max_cg_iterations = std::max(result.max_cg_iterations, cg.iterations);
    if (!cg.converged) {
      ++result.unconverged_steps;
      log << "step " << k << ": CG hit the cap of " << scenario.solver.cg_max_iterations
          << " iterations: relative residual " << format_number(cg.relative_residual) << " > "
          << format_number(scenario.solver.cg_tolerance)
          << ". Small residual: raise solver.cg_max_iterations. Large or NaN: the system is not"
             " SPD (negative stiffness, bad element).\n";
    }
    record(k);
    if (vtk && k % vtk_every == 0) vtk->write_frame(t, positions);
    progress.update(k, "CG " + std::to_string(cg.iterations) + " it");
  }
  progress.finish();

  write_file_atomically(output.staged("observations.csv"), format_observations_csv(table));
  if (sampler) write_file_atomically(output.staged("pointcloud.csv"), format_point_cloud_csv(cloud));
  write_file_atomically(output.staged("truth.csv"), format_truth_csv(truth));
  auto effects_json = [](const std::vector<EffectValue>& effects) {
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const EffectValue& effect : effects) list.push_back({{"name", effect.name}, {"value", effect.value}});
    return list;
  };
  nlohmann::ordered_json truth_json = {{"format", "sigmafem-truth/1"},
                                       {"scenario", scenario.name},
                                       {"seed", options.seed},
                                       {"declared_effects", effects_json(scenario.effects)},
                                       {"injected_effects", effects_json(options.inject)},
                                       {"truth_mesh", truth_mesh_json(truth_mesh, options.truth_mesh)},
                                       {"faults", {{"outliers", options.outliers},
                                                   {"dropouts", options.dropouts},
                                                   {"gap_steps", options.gap_steps},
                                                   {"outlier_point_steps", result.outliers},
                                                   {"dropout_point_steps", result.dropouts}}}};
  if (sampler)
    truth_json["surface_cloud"] = {{"points_per_frame", scenario.observations.surface_cloud->points_per_frame},
                                   {"frame_rate_hz", options.frame_rate > 0.0 ? nlohmann::ordered_json(options.frame_rate)
                                                                               : nlohmann::ordered_json(nullptr)},
                                   {"frame_jitter_s", options.frame_jitter},
                                   {"frames_on_steps", options.frames_on_steps},
                                   {"coverage", scenario.observations.surface_cloud->coverage},
                                   {"visible_triangles", sampler->visible_triangles().size()},
                                   {"visible_area_m2", sampler->visible_area_at_rest()},
                                   {"frames", cloud.frames.size()},
                                   {"points", cloud.point_count()}};
  if (!sampler && options.frame_rate > 0.0)
    truth_json["tracked_frames"] = {{"frame_rate_hz", options.frame_rate},
                                    {"frame_jitter_s", options.frame_jitter},
                                    {"frames_on_steps", options.frames_on_steps},
                                    {"frames", frame_times.size()}};
  write_file_atomically(output.staged("truth.json"), truth_json.dump(2) + "\n");
  if (vtk) {
    vtk->finish();
    result.vtk_frames = vtk->frame_count();
  }
  output.publish();
  result.steps = steps;
  result.truth_mesh = truth_mesh.description;
  result.truth_nodes = model.node_count();
  result.truth_tetrahedra = model.element_count();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace sigmafem
