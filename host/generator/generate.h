// generate: the synthetic-data generator (`sigmafem generate`). It runs the scenario's
// experiment on the CPU reference (or on a device back end, one simulation) with the true
// ligament stiffnesses and the events (a cut),
// and writes what a tracking system would have measured:
//   <out>/observations.csv  SO position and observed node positions per step, with Gaussian
//                           noise of the scenario's noise_std (docs/FORMATS.md)
//   <out>/pointcloud.csv    with observations.surface_cloud: the surface points of each frame
//                           (host/generator/surface_cloud_sampler.h), with the same noise
//                           (docs/FORMATS.md, "Point clouds")
//   <out>/truth.csv         each ligament's true stiffness per step
//   <out>/truth.json        the effects in the data: declared in the scenario, and injected
//                           (--inject) without being declared; the mesh the truth ran on
//                           (docs/FORMATS.md)
//   <out>/<name>.pvd + <out>/vtk/*.vtu   the organ every vtk_every steps, for ParaView
// Row k of each CSV is the state after k steps (time k dt); row 0 is the rest state. A step
// uses the SO position and the ligament stiffnesses at its END time (an event at time T acts
// on every step that ends at or after T). The same scenario and seed give the same bytes.
#pragma once

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "host/common/device_options.h"
#include "host/scenario/effect_catalogue.h"
#include "host/scenario/scenario.h"

namespace sigmafem {

// Which mesh the truth is simulated on (host/generator/truth_mesh.h); neither set: the
// scenario's. At most one may be set.
struct TruthMeshOptions {
  std::optional<int> refine;        // --truth-refine: the scenario's mesh refined 1..3 more levels
  std::optional<std::string> file;  // --truth-mesh: another mesh file of the organ (mesh.file units)
  // --truth-springs: with refine, spread each spring over the refined nodes of the attachment
  // its coarse nodes stand for (host/generator/spring_spread.h), or keep it on the same nodes.
  bool spread_springs = true;
};

struct GenerateOptions {
  std::string out_dir;
  std::uint64_t seed = 1;
  int vtk_every = -1;              // -1: the scenario's output.vtk_every; 0: no VTK
  bool progress = false;           // a progress line on stderr (when it is a terminal)
  std::string backend = "cpu";     // make_ensemble's names; "cpu" is the double-precision reference
  DeviceOptions device;            // for a device back end
  // Effects put into the data but not into the scenario (`--inject NAME=VALUE`): the model
  // a filter builds from the scenario lacks them. Recorded in truth.json.
  std::vector<EffectValue> inject;
  TruthMeshOptions truth_mesh;
  // Measured data's faults (--outliers, --dropouts), from step 1 on, each point and step
  // independently: with probability `outliers` a point is reported 1-2 cm from where it is
  // (a uniformly random direction and length), with probability `dropouts` it is missing.
  // Drawn from their own random stream, so that the noise is the same with and without them.
  double outliers = 0.0;
  double dropouts = 0.0;
  // --gap-steps: tracked points are lost for runs of steps, not step by step: a point that
  // drops out stays missing for a run whose length is geometric with this mean (1: each
  // step on its own), and runs start so often that the share of missing point-steps is
  // still `dropouts` (a tracked point is lost with probability
  // dropouts / (gap_steps (1 - dropouts) + dropouts) at each step). Tracked points only.
  double gap_steps = 1.0;
  // The frames of a surface cloud (observations.surface_cloud) or of the tracked points
  // (--frame-rate, --frame-jitter, --frames-on-steps): 0, one frame at every step's time; else
  // frames at `frame_rate` Hz
  // from 1/frame_rate on, each taken at its nominal time plus Gaussian jitter of std
  // `frame_jitter` s (kept in order, within the run) and stamped with the time it was taken,
  // the organ there interpolated linearly between the two steps around it. With
  // `frames_on_steps` each frame is taken and stamped at the step nearest its nominal time
  // instead (no jitter): the same frames on the simulation's grid, to compare with. Tracked
  // points go to the row of the step each frame was taken in, stamped in observations.csv's
  // frame_time column (at most one frame per step: frame_rate <= 1 / dt).
  double frame_rate = 0.0;
  double frame_jitter = 0.0;
  bool frames_on_steps = false;
};

struct GenerateResult {
  int steps = 0;
  double seconds = 0.0;            // wall time of the simulation and the writing
  long long cg_iterations = 0;     // summed over steps
  int max_cg_iterations = 0;       // the most in one step
  int unconverged_steps = 0;       // steps whose CG hit solver.cg_max_iterations
  int vtk_frames = 0;
  int outliers = 0;                // point-steps moved 1-2 cm (GenerateOptions::outliers)
  int dropouts = 0;                // point-steps left missing
  double max_displacement = 0.0;   // m, largest node displacement over the run
  // The mesh the truth ran on: "the scenario's mesh", "... refined N more levels" or the file.
  std::string truth_mesh;
  int truth_nodes = 0;             // of the truth mesh
  int truth_tetrahedra = 0;
};

// Runs the experiment and writes the files. Creates out_dir if needed. Throws InputError for
// invalid truth mesh options (truth_mesh.h) or an output that cannot be written, and
// std::runtime_error if the simulation fails (non-finite state); in these cases no
// observations.csv or truth.csv is written. CG steps that hit the iteration cap are reported
// on `log` with the step and residual, and counted.
GenerateResult generate(const Scenario& scenario, const GenerateOptions& options,
                        std::ostream& log);

}  // namespace sigmafem
