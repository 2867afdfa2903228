// Element volume, orientation and degeneracy checks (mesh.h: tetrahedron_volume,
// orient_and_check).
//
// Why at load: the co-rotational element builds its rest frame from the corners, and a flat
// or inverted tetrahedron gives a singular or negative stiffness that shows up much later
// as a CG failure far from its cause. Inverted elements are only a node-order convention of
// the mesher, so they are fixed; flat ones cannot be, so they are reported.
//
// Degeneracy is judged relative to the element's own size, volume / (mean edge length)^3, so
// that the test means the same for a liver in model units and a box in metres. A regular
// tetrahedron of edge a has volume a^3 / (6 sqrt 2), ratio 0.118; we reject ratios below
// 1e-6 of that, i.e. only elements that are flat to rounding, not merely poor ones.
#include <Eigen/Geometry>  // cross()
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "host/common/input_error.h"
#include "host/mesh/mesh.h"

namespace sigmafem {

namespace {

// Volume ratio of the regular tetrahedron: a^3 / (6 sqrt 2) divided by a^3.
const double kRegularQuality = 1.0 / (6.0 * std::sqrt(2.0));
// Fraction of kRegularQuality below which an element counts as flat.
constexpr double kDegenerateFraction = 1e-6;

double mean_edge_length(const Mesh& mesh, const std::array<int, 4>& t) {
  double sum = 0.0;
  for (const auto& edge : kTetrahedronEdges) sum += (mesh.nodes[t[edge[1]]] - mesh.nodes[t[edge[0]]]).norm();
  return sum / 6.0;
}

std::string three_digits(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

}  // namespace

double tetrahedron_volume(const Mesh& mesh, int e) {
  const std::array<int, 4>& t = mesh.tetrahedra[e];
  const Eigen::Vector3d& a = mesh.nodes[t[0]];
  return (mesh.nodes[t[1]] - a).cross(mesh.nodes[t[2]] - a).dot(mesh.nodes[t[3]] - a) / 6.0;
}

MeshQualityReport orient_and_check(Mesh& mesh, const std::string& source) {
  // First pass only reads, so that a mesh that fails is left exactly as it was given.
  const int nodes = mesh.node_count();
  MeshQualityReport report;
  report.min_quality = mesh.tetrahedra.empty() ? 0.0 : HUGE_VAL;
  int degenerate = 0;
  std::string first_degenerate;
  for (int e = 0; e < mesh.tetrahedron_count(); ++e) {
    const std::array<int, 4>& t = mesh.tetrahedra[e];
    for (const int node : t) {
      if (node < 0 || node >= nodes) {
        throw InputError("mesh " + source + ": tetrahedron " + std::to_string(e) +
                         " refers to node " + std::to_string(node) + ", but the mesh has " +
                         std::to_string(nodes) + " nodes");
      }
    }
    const double volume = std::abs(tetrahedron_volume(mesh, e));
    const double edge = mean_edge_length(mesh, t);
    const double quality = volume / (edge * edge * edge);
    // Written as !(x >= limit) so that a NaN (coincident corners: 0/0) counts as degenerate.
    if (!(quality >= kDegenerateFraction * kRegularQuality)) {
      if (degenerate++ == 0) {
        first_degenerate = "tetrahedron " + std::to_string(e) + " (nodes " + std::to_string(t[0]) +
                           " " + std::to_string(t[1]) + " " + std::to_string(t[2]) + " " +
                           std::to_string(t[3]) + ") is degenerate: volume " +
                           three_digits(volume) + " m^3, mean edge " + three_digits(edge) + " m";
      }
      continue;
    }
    report.min_quality = std::min(report.min_quality, quality);
    report.total_volume += volume;
  }
  if (degenerate > 0) {
    throw InputError("mesh " + source + ": " + first_degenerate +
                     ". Degenerate tetrahedra in all: " + std::to_string(degenerate) +
                     " (element and node numbers are 0-based, in file order); remesh without "
                     "flat elements");
  }
  for (int e = 0; e < mesh.tetrahedron_count(); ++e) {
    if (tetrahedron_volume(mesh, e) < 0.0) {
      // Swapping two corners reverses the orientation and changes nothing else.
      std::swap(mesh.tetrahedra[e][2], mesh.tetrahedra[e][3]);
      ++report.inverted_reordered;
    }
  }
  return report;
}

}  // namespace sigmafem
