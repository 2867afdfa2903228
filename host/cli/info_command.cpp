// `sigmafem info SCENARIO`: what a scenario resolves to (mesh size and quality, node sets),
// to check a scenario before a long run.
#include <algorithm>
#include <iostream>
#include <map>
#include <memory>
#include <string>

#include "host/cli/commands.h"
#include "host/common/input_error.h"
#include "host/mesh/mesh.h"
#include "host/scenario/scenario.h"

namespace sigmafem::cli {

namespace {

void print_nodes(std::ostream& out, const std::vector<int>& nodes) {
  out << nodes.size() << " nodes [";
  for (std::size_t i = 0; i < nodes.size(); ++i) out << (i ? " " : "") << nodes[i];
  out << "]\n";
}

// The mesh file's labels and how many tetrahedra carry each ("3 (120), 5 (476) from physical
// groups"), or why there are none.
std::string label_counts(const Mesh& mesh) {
  if (mesh.labels.empty()) return "none (" + (mesh.labels_from.empty() ? std::string("not read from a file") : mesh.labels_from) + ")";
  std::map<int, int> count;
  for (int label : mesh.labels) ++count[label];
  std::string text;
  for (const auto& [label, tetrahedra] : count)
    text += (text.empty() ? "" : ", ") + std::to_string(label) + " (" + std::to_string(tetrahedra) + ")";
  return text + " from " + mesh.labels_from;
}

}  // namespace

Action add_info_command(CLI::App& app) {
  auto scenario_path = std::make_shared<std::string>();
  CLI::App* sub = app.add_subcommand("info", "Load a scenario, check it and describe it");
  sub->add_option("scenario", *scenario_path, "Scenario JSON file")->required();
  return [scenario_path]() {
    const Scenario s = load_scenario(*scenario_path);
    std::cout << "scenario " << s.name << " (" << s.path << ")\n"
              << "  mesh " << s.mesh_spec.resolved_path << ": " << s.mesh.node_count()
              << " nodes, " << s.mesh.tetrahedron_count() << " tetrahedra, "
              << boundary_faces(s.mesh).size() << " boundary faces, volume "
              << s.mesh_report.total_volume << " m^3, " << s.mesh_report.inverted_reordered
              << " inverted tetrahedra reordered\n"
              << "  mesh labels (for regions' \"label\"): " << label_counts(s.mesh) << "\n"
              << "  material E " << s.material.young_modulus << " Pa, nu " << s.material.poisson_ratio << ", density "
              << s.material.density << " kg/m^3, "
              << (s.material.rotation == ElementRotation::polar ? "polar" : "qr") << " element rotations\n"
              << "  time " << s.time.steps << " steps of " << s.time.dt << " s\n";
    for (const Ligament& ligament : s.ligaments) {
      std::cout << "  ligament " << ligament.name << " " << ligament.stiffness << " N/m: ";
      print_nodes(std::cout, ligament.nodes);
    }
    for (const Region& region : s.regions) {
      const bool estimated = s.filter && std::find(s.filter->estimate_regions.begin(), s.filter->estimate_regions.end(),
                                                   s.region_index(region.name)) != s.filter->estimate_regions.end();
      std::cout << "  region " << region.name << ": E " << region.young_modulus << " Pa"
                << (estimated ? " (estimated, " + young_modulus_parameter_name(region.name) + ")" : "") << ", "
                << region.elements.size() << " tetrahedra"
                << (region.label ? " labelled " + std::to_string(*region.label) : std::string()) << "\n";
    }
    for (const Ligament& region : s.candidate_regions) {
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (int node : region.nodes) centre += s.mesh.nodes[static_cast<std::size_t>(node)] / region.nodes.size();
      std::cout << "  candidate region " << region.name << " (extra_ligament:" << region.name << ") around ("
                << centre.x() << ", " << centre.y() << ", " << centre.z() << ") m: ";
      print_nodes(std::cout, region.nodes);
    }
    for (const EffectValue& effect : s.effects)
      std::cout << "  declared effect " << format_effect_assignment(effect) << "\n";
    std::cout << "  control " << s.control.stiffness << " N/m: ";
    print_nodes(std::cout, s.control.nodes);
    for (const Event& event : s.events)
      std::cout << "  event t=" << event.time << " s: " << event.ligament_name << " -> "
                << event.stiffness << " N/m\n";
    if (const auto& cloud = s.observations.surface_cloud) {
      std::cout << "  observed: a surface cloud of " << cloud->points_per_frame << " points per frame, view direction "
                << message_point(cloud->view_direction) << ", coverage " << cloud->coverage << " of the depth\n";
      return 0;
    }
    std::cout << "  observed: ";
    print_nodes(std::cout, s.observations.nodes);
    for (std::size_t k = 0; k < s.observations.points.size(); ++k) {
      const ObservedPoint& point = s.observations.observed[s.observations.nodes.size() + k];
      std::cout << "  observed point " << k << " at " << message_point(s.observations.points[k])
                << ": nodes";
      for (std::size_t c = 0; c < 4; ++c)
        if (point.weights[c] != 0.0) std::cout << " " << point.nodes[c] << " (" << point.weights[c] << ")";
      std::cout << "\n";
    }
    return 0;
  };
}

}  // namespace sigmafem::cli
