#include "host/cli/report.h"

#include <cstdio>
#include <filesystem>
#include <string>

namespace sigmafem::cli {

void print_generate_summary(std::ostream& out, const Scenario& scenario,
                            const GenerateOptions& options, const GenerateResult& result) {
  const std::filesystem::path dir(options.out_dir);
  char line[256];
  std::snprintf(line, sizeof line,
                "generated %d steps of '%s' (%d nodes, %d tetrahedra) in %.2f s: "
                "%.1f ms/step, CG %.1f iterations/step (max %d), largest displacement %.1f mm\n",
                result.steps, scenario.name.c_str(), result.truth_nodes,
                result.truth_tetrahedra, result.seconds,
                1e3 * result.seconds / result.steps,
                static_cast<double>(result.cg_iterations) / result.steps, result.max_cg_iterations,
                1e3 * result.max_displacement);
  out << line;
  out << "  truth simulated on " << result.truth_mesh;
  if (result.truth_nodes != scenario.mesh.node_count() ||
      result.truth_tetrahedra != scenario.mesh.tetrahedron_count())
    out << "; the model's mesh has " << scenario.mesh.node_count() << " nodes, "
        << scenario.mesh.tetrahedron_count() << " tetrahedra (observed positions interpolated at "
           "its observed nodes' rest positions)";
  out << '\n';
  if (result.unconverged_steps > 0)
    out << "  warning: CG hit its iteration cap in " << result.unconverged_steps
        << " steps (see the messages above)\n";
  if (scenario.observations.surface_cloud) {
    out << "  " << (dir / "observations.csv").string() << "  (the SO's positions)\n";
    out << "  " << (dir / "pointcloud.csv").string() << "  (" << result.steps << " frames of "
        << scenario.observations.surface_cloud->points_per_frame << " surface points, noise "
        << scenario.observations.noise_std * 1e3 << " mm, seed " << options.seed << ")\n";
  } else {
    out << "  " << (dir / "observations.csv").string() << "  ("
        << scenario.observations.observed.size() << " observed points, noise "
        << scenario.observations.noise_std * 1e3 << " mm, seed " << options.seed << ")\n";
  }
  out << "  " << (dir / "truth.csv").string() << '\n';
  if (result.vtk_frames > 0)
    out << "  " << (dir / (scenario.name + ".pvd")).string() << "  (" << result.vtk_frames
        << " frames; open in ParaView)\n";
}

}  // namespace sigmafem::cli
