#include "host/scenario/scenario_on_mesh.h"

#include <algorithm>
#include <limits>
#include <sstream>

#include "host/common/input_error.h"

namespace sigmafem {

namespace {

// The node of `mesh` nearest to p (brute force: node lists are short) and its distance.
std::pair<int, double> nearest_node(const Mesh& mesh, const Eigen::Vector3d& p) {
  int best = -1;
  double best_distance = std::numeric_limits<double>::infinity();
  for (int i = 0; i < mesh.node_count(); ++i) {
    const double d = (mesh.nodes[static_cast<std::size_t>(i)] - p).norm();
    if (d < best_distance) {
      best = i;
      best_distance = d;
    }
  }
  return {best, best_distance};
}

class Resolver {
 public:
  Resolver(const Mesh& from, const Mesh& to, std::string source)
      : from_(from), to_(to), source_(std::move(source)) {}

  // The set written as `spec` (resolved as `nodes` on the scenario's mesh) on the other mesh;
  // sorted, unique. Not for automatic regions.
  std::vector<int> resolve(const NodeSetSpec& spec, const std::vector<int>& nodes) const {
    std::vector<int> resolved;
    switch (spec.kind) {
      case NodeSetSpec::Kind::nodes:
        for (int node : nodes) resolved.push_back(coincident_node(spec, node));
        break;
      case NodeSetSpec::Kind::near:
        resolved = select_nodes_near(to_, spec.near, spec.radius);
        if (resolved.empty())
          fail(spec.field + ".select", "near " + message_point(spec.near) + ", radius " +
                                           message_number(spec.radius) +
                                           " m selects no node of this mesh");
        break;
      case NodeSetSpec::Kind::box:
        resolved = select_nodes_in_box(to_, spec.min, spec.max);
        if (resolved.empty())
          fail(spec.field + ".select", "box min " + message_point(spec.min) + ", max " +
                                           message_point(spec.max) + " m selects no node of this mesh");
        break;
      case NodeSetSpec::Kind::automatic:
        break;   // resolve_automatic_regions
    }
    std::sort(resolved.begin(), resolved.end());
    resolved.erase(std::unique(resolved.begin(), resolved.end()), resolved.end());
    return resolved;
  }

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw InputError(source_ + ": " + field + ": " + what);
  }

 private:
  int coincident_node(const NodeSetSpec& spec, int node) const {
    const Eigen::Vector3d& p = from_.nodes[static_cast<std::size_t>(node)];
    const auto [nearest, distance] = nearest_node(to_, p);
    if (distance > kCoincidentTolerance) {
      std::ostringstream what;
      what << "node " << node << " at " << message_point(p) << " m has no node of this mesh within "
           << kCoincidentTolerance << " m (the nearest, node " << nearest << ", is "
           << distance * 1e3 << " mm away); list nodes that both meshes have, or give the set "
           << "by position (\"select\")";
      fail(spec.field + ".nodes", what.str());
    }
    return nearest;
  }

  const Mesh& from_;
  const Mesh& to_;
  std::string source_;
};

// Automatic candidate regions on the other mesh: every boundary node that no ligament or the
// control holds goes to the region of the nearest scenario node of any automatic region.
void resolve_automatic_regions(const Scenario& scenario, const Resolver& resolver, Scenario& s) {
  std::vector<std::pair<int, std::size_t>> seeds;   // scenario node, region index
  for (std::size_t r = 0; r < scenario.candidate_regions.size(); ++r)
    if (scenario.candidate_regions[r].selection.kind == NodeSetSpec::Kind::automatic)
      for (int node : scenario.candidate_regions[r].nodes) seeds.push_back({node, r});
  if (seeds.empty()) return;
  std::vector<int> held = s.control.nodes;
  for (const Ligament& ligament : s.ligaments) held.insert(held.end(), ligament.nodes.begin(), ligament.nodes.end());
  std::sort(held.begin(), held.end());
  for (int node : boundary_nodes(s.mesh)) {
    if (std::binary_search(held.begin(), held.end(), node)) continue;
    const Eigen::Vector3d& p = s.mesh.nodes[static_cast<std::size_t>(node)];
    std::size_t region = seeds.front().second;
    double best = std::numeric_limits<double>::infinity();
    for (const auto& [seed, r] : seeds) {
      const double d = (scenario.mesh.nodes[static_cast<std::size_t>(seed)] - p).squaredNorm();
      if (d < best) {
        best = d;
        region = r;
      }
    }
    s.candidate_regions[region].nodes.push_back(node);   // boundary_nodes is sorted
  }
  for (const Ligament& region : s.candidate_regions)
    if (region.nodes.empty()) resolver.fail(region.selection.field, "no boundary node of this mesh is nearest to this region");
}

}  // namespace

Scenario scenario_on_mesh(const Scenario& scenario, Mesh mesh, const std::string& source) {
  Scenario s = scenario;
  s.mesh = std::move(mesh);
  const Resolver resolver(scenario.mesh, s.mesh, source);
  for (Ligament& ligament : s.ligaments) ligament.nodes = resolver.resolve(ligament.selection, ligament.nodes);
  s.control.nodes = resolver.resolve(s.control.selection, s.control.nodes);
  for (Ligament& region : s.candidate_regions) region.nodes = resolver.resolve(region.selection, region.nodes);
  resolve_automatic_regions(scenario, resolver, s);
  // A region is selected again (by element centroids or label): on a finer mesh its border
  // follows the finer elements, as a real inclusion's would not follow the model's.
  for (Region& region : s.regions) {
    region.elements = region_elements(s.mesh, region);
    if (region.elements.empty())
      throw InputError(source + ": " + region.selection.field + ": " +
                       (region.label ? "no tetrahedron of this mesh has label " + std::to_string(*region.label)
                                     : std::string("holds the centroid of no tetrahedron of this mesh")));
  }
  // The observed points are located on the other mesh by the caller (host/generator/truth_mesh.h).
  s.observations.nodes.clear();
  s.observations.points.clear();
  s.observations.observed.clear();
  return s;
}

}  // namespace sigmafem
