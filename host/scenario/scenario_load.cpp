// load_scenario(): reads a scenario JSON file (docs/FORMATS.md, "sigmafem-scenario/1"),
// checks every field, loads the mesh and resolves node sets to indices.
//
// Every problem is an InputError "scenario FILE: FIELD: what is wrong", FIELD being the
// path of the field as a user would point at it (`time.dt`, `ligaments[1] "middle".stiffness`,
// `events[0].ligament`), so a message can be acted on without reading this code. Unknown
// fields are errors at every level: in a hand-written file a typo ("stifness") would
// otherwise silently fall back to a default. Units are SI throughout.
#include <algorithm>
#include <cctype>
#include <climits>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "host/common/input_error.h"
#include "host/common/input_file.h"
#include "host/common/physical_limits.h"
#include "host/mesh/mesh_locate.h"
#include "host/mesh/text_cursor.h"
#include "host/scenario/checked_json.h"
#include "host/scenario/scenario.h"
#include "host/scenario/surface_regions.h"

namespace sigmafem {

namespace {

using checked_json::Checker;
using checked_json::child;
using checked_json::describe;
using checked_json::element;
using checked_json::in_quotes;
using checked_json::join;
using checked_json::json;
using checked_json::suggestion;
namespace fs = std::filesystem;

constexpr const char* kFormat = "sigmafem-scenario/1";

// mesh.refine: each level multiplies the tetrahedra by 8, so 3 levels (x512) already turn a
// 10k-element mesh into millions; beyond that a finer mesh file is the better tool.
constexpr int kMaxMeshRefine = 3;

// Which nodes some tetrahedron uses. The mesh keeps the others (file indices stay valid), but
// such a node is no part of the body: it never moves, so it can be no ligament, grip or
// observed point.
std::vector<bool> nodes_of_the_body(const Mesh& mesh) {
  std::vector<bool> used(static_cast<size_t>(mesh.node_count()), false);
  for (const std::array<int, 4>& tetrahedron : mesh.tetrahedra)
    for (int node : tetrahedron) used[static_cast<size_t>(node)] = true;
  return used;
}

// A list of node indices: integers in range, each once. Keeps the order written.
std::vector<int> node_indices(const Checker& c, const json& value, const std::string& path,
                              const Mesh& mesh) {
  c.array(value, path);
  const std::vector<bool> of_the_body = nodes_of_the_body(mesh);
  std::vector<int> nodes;
  std::set<int> seen;
  for (size_t i = 0; i < value.size(); ++i) {
    const std::string at = element(path, i);
    const int node = c.integer(value[i], at);
    c.require(node >= 0 && node < mesh.node_count(), at,
              "node " + std::to_string(node) + " does not exist; the mesh has " +
                  std::to_string(mesh.node_count()) + " nodes (indices 0 to " +
                  std::to_string(mesh.node_count() - 1) + ")");
    // A repeat is a slip, and it would also change n in the per-node stiffness k/n.
    c.require(seen.insert(node).second, at, "node " + std::to_string(node) + " is listed twice");
    c.require(of_the_body[static_cast<size_t>(node)], at,
              "node " + std::to_string(node) + " belongs to no tetrahedron of the mesh, so it never moves");
    nodes.push_back(node);
  }
  return nodes;
}

// A `select` object: near + radius, or box {min, max}, checked into `spec` (kind near or box).
// `asked` says what was selected and `advice` what to enlarge, for an empty-set message.
void read_select(const Checker& c, const json& select, const std::string& select_path, NodeSetSpec& spec,
                 std::string& asked, std::string& advice) {
  c.check_object(select, select_path, {"near", "radius", "box"}, {});
  const bool has_sphere = select.contains("near") || select.contains("radius");
  const bool has_box = select.contains("box");
  c.require(!(has_sphere && has_box), select_path,
            "give either \"near\" + \"radius\" or \"box\", not both");
  c.require(has_sphere || has_box, select_path,
            "empty selection: give \"near\" + \"radius\" or \"box\": {\"min\", \"max\"}");
  if (has_sphere) {
    c.check_object(select, select_path, {"near", "radius"}, {"near", "radius"});
    spec.near = c.vector3(select.at("near"), child(select_path, "near"));
    spec.radius = c.number(select.at("radius"), child(select_path, "radius"));
    c.positive(spec.radius, child(select_path, "radius"));
    spec.kind = NodeSetSpec::Kind::near;
    asked = "near " + message_point(spec.near) + ", radius " + message_number(spec.radius) + " m";
    advice = "radius";
  } else {
    const std::string box_path = child(select_path, "box");
    const json& box = select.at("box");
    c.check_object(box, box_path, {"min", "max"}, {"min", "max"});
    spec.min = c.vector3(box.at("min"), child(box_path, "min"));
    spec.max = c.vector3(box.at("max"), child(box_path, "max"));
    c.require((spec.min.array() <= spec.max.array()).all(), box_path,
              "min " + message_point(spec.min) + " exceeds max " + message_point(spec.max) +
                  " in some coordinate");
    spec.kind = NodeSetSpec::Kind::box;
    asked = "box min " + message_point(spec.min) + ", max " + message_point(spec.max) + " m";
    advice = "the box";
  }
}

// The node set of a ligament or of the control: `nodes` or `select` (near + radius, or box),
// in the transformed frame. Returns sorted, unique indices; an empty set is an error. `spec`
// gets how the set was written.
std::vector<int> node_set(const Checker& c, const json& owner, const std::string& path,
                          const Mesh& mesh, NodeSetSpec& spec) {
  spec = NodeSetSpec();
  spec.field = path;
  const bool has_nodes = owner.contains("nodes");
  const bool has_select = owner.contains("select");
  c.require(!(has_nodes && has_select), path, "give either \"nodes\" or \"select\", not both");
  c.require(
      has_nodes || has_select, path,
      "missing node set: give \"nodes\" (node indices) or \"select\" (near + radius, or box)");
  std::vector<int> nodes;
  std::string asked;   // the selection, for the empty-set message
  std::string advice;  // what to change
  if (has_nodes) {
    nodes = node_indices(c, owner.at("nodes"), child(path, "nodes"), mesh);
    std::sort(nodes.begin(), nodes.end());
    asked = "\"nodes\" is an empty list";
    advice = "list at least one node";
  } else {
    read_select(c, owner.at("select"), child(path, "select"), spec, asked, advice);
    nodes = spec.kind == NodeSetSpec::Kind::near ? select_nodes_near(mesh, spec.near, spec.radius)
                                                 : select_nodes_in_box(mesh, spec.min, spec.max);
    advice = "enlarge " + advice + " or list nodes";
    // With a mesh scale set, a selection written in file units is the usual cause.
    advice += " (selections are in metres, after mesh scale and translate)";
  }
  if (has_select) {   // a selection takes the body's nodes only
    const std::vector<bool> of_the_body = nodes_of_the_body(mesh);
    nodes.erase(std::remove_if(nodes.begin(), nodes.end(), [&](int node) { return !of_the_body[static_cast<size_t>(node)]; }),
                nodes.end());
  }
  c.require(!nodes.empty(), path, "node set is empty (" + asked + "); " + advice);
  return nodes;
}

// The scenario's name becomes part of output file names (NAME.pvd, vtk/NAME_000000.vtu) and
// of plot titles: no folder separators, no "..", no quotes or control characters.
constexpr const char* kFileNameRule =
    "1 to 64 letters, digits, '_', '-' or '.', starting with a letter or digit";

bool is_file_name_safe(const std::string& name) {
  if (name.empty() || name.size() > 64 || !std::isalnum(static_cast<unsigned char>(name[0]))) return false;
  return std::all_of(name.begin(), name.end(), [](char ch) {
    return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-' || ch == '.';
  });
}

// A ligament name becomes a CSV column header (truth and estimates files) and is looked
// up by events and the filter; keep it to characters that survive that.
bool valid_name(const std::string& name) {
  if (name.empty() || name.front() == ' ' || name.back() == ' ') return false;
  return std::none_of(name.begin(), name.end(), [](char ch) {
    return ch == ',' || ch == '"' || static_cast<unsigned char>(ch) < 0x20;
  });
}

// Index of the ligament called `name`, or a failure naming the ligaments there are.
int ligament_by_name(const Checker& c, const std::vector<Ligament>& ligaments, const json& value,
                     const std::string& path) {
  const std::string name = c.string(value, path);
  std::vector<std::string> names;
  for (size_t i = 0; i < ligaments.size(); ++i) {
    if (ligaments[i].name == name) return static_cast<int>(i);
    names.push_back(ligaments[i].name);
  }
  c.fail(path, "no ligament named " + in_quotes(name) + suggestion(name, names) +
                   "; ligaments: " + (names.empty() ? "(none)" : join(names)));
}


// Paths in a scenario are relative to its folder, so a scenario and its files move together.
std::string resolve(const std::string& scenario_path, const std::string& file) {
  return (fs::path(scenario_path).parent_path() / file).lexically_normal().string();
}

// ---------------------------------------------------------------------------------------
// The sections, in the order of docs/FORMATS.md.

void read_mesh_section(const Checker& c, const json& root, const std::string& scenario_path,
                       Scenario& s) {
  const json& spec = root.at("mesh");
  c.check_object(spec, "mesh", {"file", "scale", "translate", "refine"}, {"file"});
  s.mesh_spec.file = c.string(spec.at("file"), "mesh.file");
  c.require(!s.mesh_spec.file.empty(), "mesh.file", "empty file name");
  s.mesh_spec.scale = c.number_or(spec, "mesh", "scale", 1.0);
  c.positive(s.mesh_spec.scale, "mesh.scale");
  if (spec.contains("translate"))
    s.mesh_spec.translate = c.vector3(spec.at("translate"), "mesh.translate");
  s.mesh_spec.refine = c.integer_or(spec, "mesh", "refine", 0);
  c.require(s.mesh_spec.refine >= 0 && s.mesh_spec.refine <= kMaxMeshRefine, "mesh.refine",
            "must be an integer from 0 to " + std::to_string(kMaxMeshRefine) +
                " (uniform refinement levels, each splits every tetrahedron into 8), found " +
                std::to_string(s.mesh_spec.refine));
  s.mesh_spec.resolved_path = resolve(scenario_path, s.mesh_spec.file);
  std::error_code error;
  c.require(fs::is_regular_file(s.mesh_spec.resolved_path, error), "mesh.file",
            "file not found: " + s.mesh_spec.resolved_path +
                " (mesh paths are relative to the scenario's folder)");
  try {
    s.mesh = read_mesh(s.mesh_spec.resolved_path);
    transform_mesh(s.mesh, s.mesh_spec.scale, s.mesh_spec.translate);
    s.mesh_report = orient_and_check(s.mesh, s.mesh_spec.resolved_path);
  } catch (const InputError& e) {
    c.fail("mesh.file", e.what());
  }
  // Refined after orienting, so that selections (below, in read_ligaments and on) see the
  // refined nodes while the file's nodes keep their indices for explicit node lists.
  if (s.mesh_spec.refine == 0) return;
  for (int level = 0; level < s.mesh_spec.refine; ++level) s.mesh = refine_uniform(s.mesh);
  // The children of positive parents are positive, so this only measures the new elements;
  // the count of inverted elements the file had stays the one reported for the file.
  try {
    const MeshQualityReport refined = orient_and_check(s.mesh, s.mesh_spec.resolved_path);
    s.mesh_report.min_quality = refined.min_quality;
    s.mesh_report.total_volume = refined.total_volume;
  } catch (const InputError& e) {
    c.fail("mesh.refine", e.what());  // element numbers there are those of the refined mesh
  }
}

void read_physics(const Checker& c, const json& root, Scenario& s) {
  const json& material = root.at("material");
  c.check_object(material, "material", {"young_modulus", "poisson_ratio", "density", "rotation"},
                 {"young_modulus", "poisson_ratio", "density"});
  s.material.young_modulus = c.number(material.at("young_modulus"), "material.young_modulus");
  c.positive(s.material.young_modulus, "material.young_modulus");
  s.material.poisson_ratio = c.number(material.at("poisson_ratio"), "material.poisson_ratio");
  // nu = 0.5 is incompressible: the linear elastic stiffness has lambda -> infinity.
  c.require(s.material.poisson_ratio > -1.0 && s.material.poisson_ratio < 0.5,
            "material.poisson_ratio",
            "must be in (-1, 0.5), found " + message_number(s.material.poisson_ratio));
  s.material.density = c.number(material.at("density"), "material.density");
  c.positive(s.material.density, "material.density");
  if (material.contains("rotation")) {
    const std::string rotation = c.string(material.at("rotation"), "material.rotation");
    c.require(rotation == "qr" || rotation == "polar", "material.rotation",
              "unknown element rotation " + in_quotes(rotation) + suggestion(rotation, {"qr", "polar"}) +
                  " (expected \"qr\", SOFA's large method, or \"polar\")");
    s.material.rotation = rotation == "polar" ? ElementRotation::polar : ElementRotation::qr;
  }

  if (root.contains("damping")) {
    const json& damping = root.at("damping");
    c.check_object(damping, "damping", {"rayleigh_stiffness", "rayleigh_mass"}, {});
    s.damping.rayleigh_stiffness = c.number_or(damping, "damping", "rayleigh_stiffness", 0.0);
    c.non_negative(s.damping.rayleigh_stiffness, "damping.rayleigh_stiffness");
    s.damping.rayleigh_mass = c.number_or(damping, "damping", "rayleigh_mass", 0.0);
    c.non_negative(s.damping.rayleigh_mass, "damping.rayleigh_mass");
  }
  if (root.contains("gravity")) s.gravity = c.vector3(root.at("gravity"), "gravity");

  const json& time = root.at("time");
  c.check_object(time, "time", {"dt", "steps"}, {"dt", "steps"});
  s.time.dt = c.number(time.at("dt"), "time.dt");
  c.positive(s.time.dt, "time.dt");
  s.time.steps = c.integer(time.at("steps"), "time.steps");
  c.require(s.time.steps >= 1 && s.time.steps <= kMaxSteps, "time.steps",
            "must be 1 to " + std::to_string(kMaxSteps) + ", found " + std::to_string(s.time.steps));

  if (root.contains("solver")) {
    const json& solver = root.at("solver");
    c.check_object(solver, "solver", {"cg_max_iterations", "cg_tolerance"}, {});
    s.solver.cg_max_iterations =
        c.integer_or(solver, "solver", "cg_max_iterations", s.solver.cg_max_iterations);
    c.require(s.solver.cg_max_iterations >= 1, "solver.cg_max_iterations",
              "must be >= 1, found " + std::to_string(s.solver.cg_max_iterations));
    s.solver.cg_tolerance = c.number_or(solver, "solver", "cg_tolerance", s.solver.cg_tolerance);
    // A relative residual: 1 or more would accept the warm start unchanged.
    c.require(s.solver.cg_tolerance > 0.0 && s.solver.cg_tolerance < 1.0, "solver.cg_tolerance",
              "must be in (0, 1), found " + message_number(s.solver.cg_tolerance));
  }
}

void read_ligaments(const Checker& c, const json& root, Scenario& s) {
  if (!root.contains("ligaments")) return;
  const json& ligaments = c.array(root.at("ligaments"), "ligaments");
  for (size_t i = 0; i < ligaments.size(); ++i) {
    const json& item = ligaments[i];
    // Name the ligament in its path as soon as it is known: "ligaments[1] "middle"".
    std::string path = element("ligaments", i);
    if (item.is_object() && item.contains("name") && item.at("name").is_string()) {
      path += " " + in_quotes(item.at("name").get<std::string>());
    }
    c.check_object(item, path, {"name", "nodes", "select", "stiffness"}, {"name", "stiffness"});
    Ligament ligament;
    ligament.name = c.string(item.at("name"), child(path, "name"));
    c.require(valid_name(ligament.name), child(path, "name"),
              "not a usable name: it must be non-empty, without commas, quotes, control "
              "characters or edge spaces (it becomes a CSV column header)");
    c.require(s.ligament_index(ligament.name) < 0, child(path, "name"),
              "duplicate ligament name (also ligaments[" +
                  std::to_string(s.ligament_index(ligament.name)) + "]); names must be unique");
    ligament.nodes = node_set(c, item, path, s.mesh, ligament.selection);
    ligament.stiffness = c.number(item.at("stiffness"), child(path, "stiffness"));
    c.non_negative(ligament.stiffness, child(path, "stiffness"));
    s.ligaments.push_back(std::move(ligament));
  }
}

// regions: [{"name", "select", "young_modulus"?}], parts of the organ with a Young's modulus of
// their own (default the material's); each holds the tetrahedra whose centroid its selection
// holds, and no tetrahedron may be in two. Read after the material.
void read_regions(const Checker& c, const json& root, Scenario& s) {
  if (!root.contains("regions")) return;
  const json& regions = c.array(root.at("regions"), "regions");
  std::vector<int> region_of(static_cast<size_t>(s.mesh.tetrahedron_count()), -1);
  for (size_t i = 0; i < regions.size(); ++i) {
    const json& item = regions[i];
    std::string path = element("regions", i);
    if (item.is_object() && item.contains("name") && item.at("name").is_string())
      path += " " + in_quotes(item.at("name").get<std::string>());
    c.check_object(item, path, {"name", "select", "label", "young_modulus"}, {"name"});
    Region region;
    region.name = c.string(item.at("name"), child(path, "name"));
    c.require(valid_name(region.name), child(path, "name"),
              "not a usable name: it must be non-empty, without commas, quotes, control "
              "characters or edge spaces (it becomes a CSV column header)");
    c.require(s.region_index(region.name) < 0, child(path, "name"),
              "duplicate region name (also regions[" + std::to_string(s.region_index(region.name)) +
                  "]); names must be unique");
    c.require(item.contains("select") != item.contains("label"), path,
              "give either \"select\" (by element centroids) or \"label\" (a physical group or CELL_DATA label of the mesh file)");
    region.selection.field = path;
    if (item.contains("label")) {
      region.label = c.integer(item.at("label"), child(path, "label"));
      c.require(!s.mesh.labels.empty(), child(path, "label"),
                "mesh " + s.mesh_spec.file + " labels no element (" +
                    (s.mesh.labels_from.empty() ? "it was not read from a file" : s.mesh.labels_from) +
                    "; Gmsh files label by physical group, VTK files by a CELL_DATA array of integers)");
      region.elements = region_elements(s.mesh, region);
      std::set<int> labels(s.mesh.labels.begin(), s.mesh.labels.end());
      std::string known;
      for (int label : labels) known += (known.empty() ? "" : ", ") + std::to_string(label);
      c.require(!region.elements.empty(), child(path, "label"),
                "no tetrahedron of mesh " + s.mesh_spec.file + " has label " + std::to_string(*region.label) +
                    " (its labels: " + known + ")");
    } else {
      std::string asked, advice;
      read_select(c, item.at("select"), child(path, "select"), region.selection, asked, advice);
      region.elements = region_elements(s.mesh, region);
      c.require(!region.elements.empty(), child(path, "select"),
                "holds the centroid of no tetrahedron (" + asked + "); enlarge " + advice +
                    " (selections are in metres, after mesh scale and translate)");
    }
    for (int e : region.elements) {
      const int other = region_of[static_cast<size_t>(e)];
      if (other >= 0)
        c.fail(child(path, region.label ? "label" : "select"), "tetrahedron " + std::to_string(e) + " is also in regions[" +
                                          std::to_string(other) + "] " + in_quotes(s.regions[static_cast<size_t>(other)].name) +
                                          "; a tetrahedron has one Young's modulus, so regions must not overlap");
      region_of[static_cast<size_t>(e)] = static_cast<int>(i);
    }
    region.young_modulus = c.number_or(item, path, "young_modulus", s.material.young_modulus);
    c.positive(region.young_modulus, child(path, "young_modulus"));
    s.regions.push_back(std::move(region));
  }
}

// candidate_regions, the regions of extra_ligament:NAME: a list [{"name", "nodes" | "select"}],
// or {"automatic": N} for N surface patches; left out: kAutomaticRegionCount patches. Read
// after the ligaments and the control, whose nodes the patches leave out.
void read_candidate_regions(const Checker& c, const json& root, Scenario& s) {
  int automatic = kAutomaticRegionCount;
  if (root.contains("candidate_regions") && root.at("candidate_regions").is_object()) {
    const json& object = root.at("candidate_regions");
    c.check_object(object, "candidate_regions", {"automatic"}, {"automatic"});
    automatic = c.integer(object.at("automatic"), "candidate_regions.automatic");
    c.require(automatic >= 0 && automatic <= 64, "candidate_regions.automatic", "must be an integer from 0 to 64");
  } else if (root.contains("candidate_regions")) {
    const json& regions = c.array(root.at("candidate_regions"), "candidate_regions");
    for (size_t i = 0; i < regions.size(); ++i) {
      const std::string path = element("candidate_regions", i);
      c.check_object(regions[i], path, {"name", "nodes", "select"}, {"name"});
      Ligament region;
      region.name = c.string(regions[i].at("name"), child(path, "name"));
      c.require(valid_name(region.name) && region.name.find(':') == std::string::npos, child(path, "name"),
                "not a usable name: it must be non-empty, without colons, commas, quotes, control "
                "characters or edge spaces");
      c.require(s.candidate_region_index(region.name) < 0, child(path, "name"),
                "duplicate region name; names must be unique");
      region.nodes = node_set(c, regions[i], path, s.mesh, region.selection);
      s.candidate_regions.push_back(std::move(region));
    }
    return;
  }
  std::vector<int> held = s.control.nodes;
  for (const Ligament& ligament : s.ligaments) held.insert(held.end(), ligament.nodes.begin(), ligament.nodes.end());
  s.candidate_regions = automatic_surface_regions(s.mesh, automatic, held);
  for (Ligament& region : s.candidate_regions) {
    region.selection.kind = NodeSetSpec::Kind::automatic;
    region.selection.field = "candidate_regions " + in_quotes(region.name) + " (automatic)";
  }
}

Trajectory read_trajectory(const Checker& c, const json& value, const std::string& path,
                           const std::string& scenario_path) {
  c.check_object(value, path, {"type", "velocity", "times", "positions", "file"}, {"type"});
  const std::string type = c.string(value.at("type"), child(path, "type"));
  Trajectory trajectory;
  if (type == "linear") {
    c.check_object(value, path, {"type", "velocity"}, {"velocity"});
    trajectory.type = Trajectory::Type::linear;
    trajectory.velocity = c.vector3(value.at("velocity"), child(path, "velocity"));
  } else if (type == "waypoints") {
    c.check_object(value, path, {"type", "times", "positions"}, {"times", "positions"});
    trajectory.type = Trajectory::Type::waypoints;
    const std::string times_path = child(path, "times");
    const std::string positions_path = child(path, "positions");
    const json& times = c.array(value.at("times"), times_path);
    const json& positions = c.array(value.at("positions"), positions_path);
    c.require(!times.empty(), times_path, "needs at least one waypoint");
    c.require(times.size() == positions.size(), positions_path,
              std::to_string(positions.size()) + " positions for " + std::to_string(times.size()) +
                  " times; give one position [x, y, z] per time");
    for (size_t i = 0; i < times.size(); ++i) {
      const double t = c.number(times[i], element(times_path, i));
      c.require(trajectory.times.empty() || t > trajectory.times.back(), element(times_path, i),
                "time " + message_number(t) + " does not come after the previous time " +
                    (trajectory.times.empty() ? "" : message_number(trajectory.times.back())) +
                    "; times must strictly increase");
      trajectory.times.push_back(t);
      trajectory.positions.push_back(c.vector3(positions[i], element(positions_path, i)));
    }
  } else if (type == "file") {
    c.check_object(value, path, {"type", "file"}, {"file"});
    const std::string file_path = child(path, "file");
    const std::string file = c.string(value.at("file"), file_path);
    c.require(!file.empty(), file_path, "empty file name");
    const std::string resolved = resolve(scenario_path, file);
    std::error_code error;
    c.require(fs::is_regular_file(resolved, error), file_path,
              "file not found: " + resolved + " (paths are relative to the scenario's folder)");
    try {
      trajectory = read_trajectory_csv(resolved);
    } catch (const InputError& e) {
      c.fail(file_path, e.what());
    }
    trajectory.file = file;
  } else {
    c.fail(child(path, "type"), "unknown trajectory type " + in_quotes(type) +
                                    suggestion(type, {"linear", "waypoints", "file"}) +
                                    "; expected linear, waypoints or file");
  }
  return trajectory;
}

void read_control(const Checker& c, const json& root, const std::string& scenario_path,
                  Scenario& s) {
  const json& control = root.at("control");
  c.check_object(control, "control", {"nodes", "select", "stiffness", "trajectory"},
                 {"stiffness", "trajectory"});
  s.control.nodes = node_set(c, control, "control", s.mesh, s.control.selection);
  s.control.stiffness = c.number(control.at("stiffness"), "control.stiffness");
  c.non_negative(s.control.stiffness, "control.stiffness");
  s.control.trajectory =
      read_trajectory(c, control.at("trajectory"), "control.trajectory", scenario_path);
  // so(0): the SO's offsets to its nodes are taken at rest, so at t = 0 no spring pulls.
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int node : s.control.nodes) sum += s.mesh.nodes[static_cast<size_t>(node)];
  s.control.start = sum / static_cast<double>(s.control.nodes.size());
}

void read_events(const Checker& c, const json& root, Scenario& s) {
  if (!root.contains("events")) return;
  const json& events = c.array(root.at("events"), "events");
  for (size_t i = 0; i < events.size(); ++i) {
    const std::string path = element("events", i);
    c.check_object(events[i], path, {"time", "ligament", "stiffness"},
                   {"time", "ligament", "stiffness"});
    Event event;
    event.time = c.number(events[i].at("time"), child(path, "time"));
    c.non_negative(event.time, child(path, "time"));
    event.ligament =
        ligament_by_name(c, s.ligaments, events[i].at("ligament"), child(path, "ligament"));
    event.ligament_name = s.ligaments[static_cast<size_t>(event.ligament)].name;
    event.stiffness = c.number(events[i].at("stiffness"), child(path, "stiffness"));
    c.non_negative(event.stiffness, child(path, "stiffness"));
    s.events.push_back(std::move(event));
  }
  // Stable: two events at the same time apply in the order written, the last one winning.
  std::stable_sort(s.events.begin(), s.events.end(),
                   [](const Event& a, const Event& b) { return a.time < b.time; });
}

// observations.surface_cloud (SurfaceCloud). A scenario observes tracked points or a cloud:
// the two kinds of data are not combined.
void read_surface_cloud(const Checker& c, const json& observations, Scenario& s) {
  const std::string path = "observations.surface_cloud";
  const json& cloud = observations.at("surface_cloud");
  c.check_object(cloud, path, {"points_per_frame", "view_direction", "coverage"}, {});
  c.require(s.observations.observed.empty(), path,
            "a scenario observes either tracked points (observations.nodes, observations.points) or a surface "
            "cloud, not both; remove one");
  SurfaceCloud spec;
  if (cloud.contains("points_per_frame")) {
    spec.points_per_frame = c.integer(cloud.at("points_per_frame"), child(path, "points_per_frame"));
    c.require(spec.points_per_frame >= 1 && spec.points_per_frame <= kMaxCloudPoints, child(path, "points_per_frame"),
              "must be 1 to " + std::to_string(kMaxCloudPoints) + " points per frame, found " +
                  std::to_string(spec.points_per_frame));
  }
  if (cloud.contains("view_direction")) {
    const Eigen::Vector3d view = c.vector3(cloud.at("view_direction"), child(path, "view_direction"));
    c.require(view.norm() > 0.0, child(path, "view_direction"), "must not be zero: it is the direction the camera looks in");
    spec.view_direction = view.normalized();
  }
  if (cloud.contains("coverage")) {
    spec.coverage = c.number(cloud.at("coverage"), child(path, "coverage"));
    c.require(spec.coverage > 0.0 && spec.coverage <= 1.0, child(path, "coverage"),
              "must be a share of the organ's depth in (0, 1], found " + message_number(spec.coverage));
  }
  s.observations.surface_cloud = spec;
}

void read_observations(const Checker& c, const json& root, Scenario& s) {
  if (!root.contains("observations")) return;
  const json& observations = root.at("observations");
  c.check_object(observations, "observations", {"nodes", "points", "surface_cloud", "noise_std"}, {});
  if (observations.contains("nodes")) {
    // Scenario order is kept: it is the column order of the observations CSV.
    s.observations.nodes = node_indices(c, observations.at("nodes"), "observations.nodes", s.mesh);
  }
  s.observations.observed = ObservedPoints(s.observations.nodes);
  if (observations.contains("points")) {
    // Each point is located on the mesh (host/mesh/mesh_locate.h) and observed as the material
    // point there; one a little outside (a surface measured on a finer geometry) as the
    // nearest point of the mesh.
    const json& points = c.array(observations.at("points"), "observations.points");
    const double limit = kMaxOutsideShare * bounding_diagonal(s.mesh);
    for (size_t i = 0; i < points.size(); ++i) {
      const std::string path = element("observations.points", i);
      const Eigen::Vector3d point = c.vector3(points[i], path);
      const MeshLocation location = locate_point(s.mesh, point);
      c.require(location.outside_distance <= limit, path,
                message_point(point) + " lies " + message_number(location.outside_distance * 1e3) +
                    " mm outside the mesh, more than " + message_number(kMaxOutsideShare * 100) +
                    "% of its size (give points in metres, in the mesh's frame after mesh.scale "
                    "and mesh.translate, on or inside the organ at rest)");
      s.observations.points.push_back(point);
      s.observations.observed.push_back(ObservedPoint::at(s.mesh, location));
    }
  }
  if (observations.contains("surface_cloud")) read_surface_cloud(c, observations, s);
  s.observations.noise_std = c.number_or(observations, "observations", "noise_std", 0.0);
  c.require(s.observations.noise_std >= 0.0 && s.observations.noise_std <= kMaxNoiseStd,
            "observations.noise_std",
            "must be 0 to " + message_number(kMaxNoiseStd) + " m, found " + message_number(s.observations.noise_std));
}

// The fields the filter's windowed tests share (filter.change_detection,
// filter.adaptive_noise; filter.outlier_gate has no window): enabled, window (steps),
// false_alarm (a probability).
void read_windowed_test(const Checker& c, const json& object, const std::string& path,
                        std::optional<bool>& enabled, std::optional<int>& window,
                        std::optional<double>& false_alarm) {
  if (object.contains("enabled")) {
    c.require(object.at("enabled").is_boolean(), child(path, "enabled"),
              "expected true or false, found " + object.at("enabled").dump());
    enabled = object.at("enabled").get<bool>();
  }
  if (object.contains("window")) {
    window = c.integer(object.at("window"), child(path, "window"));
    c.require(*window >= 1 && *window <= 1000, child(path, "window"), "must be 1..1000 steps");
  }
  if (object.contains("false_alarm")) {
    false_alarm = c.number(object.at("false_alarm"), child(path, "false_alarm"));
    c.require(*false_alarm > 0.0 && *false_alarm < 0.5, child(path, "false_alarm"),
              "must be a probability in (0, 0.5)");
  }
}

// Appends `index` to one of the filter's lists, refusing a repeat ("ligament \"x\"" is `what`).
void append_once(const Checker& c, std::vector<int>& list, int index, const std::string& path,
                 const std::string& what) {
  c.require(std::find(list.begin(), list.end(), index) == list.end(), path, what + " is listed twice");
  list.push_back(index);
}

// Whether the filter lists `names_key` (parameters estimated beyond the whole ligaments);
// `priors_key`, their prior medians, comes with it or not at all.
bool has_estimated_list(const Checker& c, const json& filter, const std::string& names_key,
                        const std::string& priors_key, const std::string& of_each) {
  const bool has_names = filter.contains(names_key);
  c.require(has_names == filter.contains(priors_key), has_names ? "filter" : "filter." + priors_key,
            has_names ? names_key + " needs " + priors_key + ", the prior median of each " + of_each
                      : "given without " + names_key + ", the list it is the prior of");
  return has_names;
}

// filter.PRIORS_KEY: one prior median > 0 per name of filter.NAMES_KEY (`count`, `what`).
std::vector<double> read_prior_medians(const Checker& c, const json& filter, const std::string& priors_key,
                                       const std::string& names_key, std::size_t count, const std::string& what) {
  const std::string path = "filter." + priors_key;
  const json& initial = c.array(filter.at(priors_key), path);
  c.require(initial.size() == count, path,
            std::to_string(initial.size()) + " values for " + std::to_string(count) + " " + what +
                "; give one per name in filter." + names_key + ", same order");
  std::vector<double> medians;
  for (size_t i = 0; i < initial.size(); ++i) {
    const double value = c.number(initial[i], element(path, i));
    c.positive(value, element(path, i));   // the filter works on its log
    medians.push_back(value);
  }
  return medians;
}

// filter.estimate_springs (ligament names, not in filter.estimate) and
// filter.initial_spring_stiffness (N/m per spring, one per ligament).
void read_estimated_springs(const Checker& c, const json& filter, const Scenario& s, FilterSpec& spec) {
  if (!has_estimated_list(c, filter, "estimate_springs", "initial_spring_stiffness", "spring (N/m)")) return;
  const json& names = c.array(filter.at("estimate_springs"), "filter.estimate_springs");
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string path = element("filter.estimate_springs", i);
    const int index = ligament_by_name(c, s.ligaments, names[i], path);
    const std::string& name = s.ligaments[static_cast<size_t>(index)].name;
    c.require(std::find(spec.estimate.begin(), spec.estimate.end(), index) == spec.estimate.end(), path,
              "ligament " + in_quotes(name) + " is also in filter.estimate: estimate it whole or per spring, not both");
    append_once(c, spec.estimate_springs, index, path, "ligament " + in_quotes(name));
  }
  spec.initial_spring_stiffness =
      read_prior_medians(c, filter, "initial_spring_stiffness", "estimate_springs", names.size(), "ligaments");
}

// filter.estimate_young_modulus (region names) and filter.initial_young_modulus (Pa, one each).
void read_estimated_regions(const Checker& c, const json& filter, const Scenario& s, FilterSpec& spec) {
  if (!has_estimated_list(c, filter, "estimate_young_modulus", "initial_young_modulus", "region (Pa)")) return;
  const json& names = c.array(filter.at("estimate_young_modulus"), "filter.estimate_young_modulus");
  std::string known;
  for (const Region& region : s.regions) known += (known.empty() ? "" : ", ") + region.name;
  for (size_t i = 0; i < names.size(); ++i) {
    const std::string path = element("filter.estimate_young_modulus", i);
    const std::string name = c.string(names[i], path);
    const int index = s.region_index(name);
    c.require(index >= 0, path,
              "no region " + in_quotes(name) + " (regions: " + (known.empty() ? "none declared" : known) + ")");
    append_once(c, spec.estimate_regions, index, path, "region " + in_quotes(name));
  }
  spec.initial_young_modulus =
      read_prior_medians(c, filter, "initial_young_modulus", "estimate_young_modulus", names.size(), "regions");
}

void read_filter(const Checker& c, const json& root, Scenario& s) {
  if (!root.contains("filter")) return;
  const json& filter = root.at("filter");
  c.check_object(filter, "filter",
                 {"estimate", "initial_stiffness", "estimate_springs", "initial_spring_stiffness",
                  "estimate_young_modulus", "initial_young_modulus",
                  "initial_log_std", "parameter_drift_log_std", "observation_std", "sigma_points",
                  "change_detection", "adaptive_noise", "outlier_gate"},
                 {"estimate", "initial_stiffness", "observation_std"});
  FilterSpec spec;
  const json& estimate = c.array(filter.at("estimate"), "filter.estimate");
  c.require(!estimate.empty() || filter.contains("estimate_springs") || filter.contains("estimate_young_modulus"),
            "filter.estimate",
            "empty: name at least one ligament (or ligament per spring, in estimate_springs, or region, in "
            "estimate_young_modulus) to estimate");
  for (size_t i = 0; i < estimate.size(); ++i) {
    const std::string path = element("filter.estimate", i);
    const int index = ligament_by_name(c, s.ligaments, estimate[i], path);
    append_once(c, spec.estimate, index, path, "ligament " + in_quotes(s.ligaments[static_cast<size_t>(index)].name));
  }
  spec.initial_stiffness =
      read_prior_medians(c, filter, "initial_stiffness", "estimate", estimate.size(), "estimated ligaments");
  read_estimated_springs(c, filter, s, spec);
  read_estimated_regions(c, filter, s, spec);
  spec.initial_log_std = c.number_or(filter, "filter", "initial_log_std", spec.initial_log_std);
  c.positive(spec.initial_log_std, "filter.initial_log_std");
  spec.parameter_drift_log_std =
      c.number_or(filter, "filter", "parameter_drift_log_std", spec.parameter_drift_log_std);
  c.non_negative(spec.parameter_drift_log_std, "filter.parameter_drift_log_std");
  // The filter divides by this variance: zero would claim perfect measurements.
  spec.observation_std = c.number(filter.at("observation_std"), "filter.observation_std");
  c.require(spec.observation_std > 0.0 && spec.observation_std <= kMaxNoiseStd, "filter.observation_std",
            "must be > 0 and at most " + message_number(kMaxNoiseStd) + " m, found " + message_number(spec.observation_std));
  if (filter.contains("sigma_points")) {
    spec.sigma_points = c.string(filter.at("sigma_points"), "filter.sigma_points");
    c.require(spec.sigma_points == "simplex" || spec.sigma_points == "star", "filter.sigma_points",
              "unknown sigma-point set " + in_quotes(spec.sigma_points) +
                  suggestion(spec.sigma_points, {"simplex", "star"}) +
                  "; expected simplex (p+1 points) or star (2p points)");
  }
  if (filter.contains("change_detection")) {
    const json& detection = filter.at("change_detection");
    const std::string path = "filter.change_detection";
    c.check_object(detection, path,
                   {"enabled", "window", "false_alarm", "hold_off", "inflation_log_std", "max_catch_up"}, {});
    ChangeDetectionSpec& d = spec.change_detection;
    read_windowed_test(c, detection, path, d.enabled, d.window, d.false_alarm);
    if (detection.contains("hold_off")) {
      d.hold_off = c.integer(detection.at("hold_off"), child(path, "hold_off"));
      c.require(*d.hold_off >= 0, child(path, "hold_off"), "must not be negative");
    }
    if (detection.contains("inflation_log_std")) {
      d.inflation_log_std = c.number(detection.at("inflation_log_std"), child(path, "inflation_log_std"));
      c.non_negative(*d.inflation_log_std, child(path, "inflation_log_std"));
    }
    if (detection.contains("max_catch_up")) {
      d.max_catch_up = c.integer(detection.at("max_catch_up"), child(path, "max_catch_up"));
      c.require(*d.max_catch_up >= 0, child(path, "max_catch_up"), "must not be negative");
    }
  }
  if (filter.contains("adaptive_noise")) {
    const json& adaptive = filter.at("adaptive_noise");
    const std::string path = "filter.adaptive_noise";
    c.check_object(adaptive, path, {"enabled", "window", "false_alarm"}, {});
    AdaptiveNoiseSpec& a = spec.adaptive_noise;
    read_windowed_test(c, adaptive, path, a.enabled, a.window, a.false_alarm);
  }
  if (filter.contains("outlier_gate")) {
    const json& gate = filter.at("outlier_gate");
    const std::string path = "filter.outlier_gate";
    c.check_object(gate, path, {"enabled", "false_alarm", "max_share"}, {});
    OutlierGateSpec& g = spec.outlier_gate;
    std::optional<int> no_window;
    read_windowed_test(c, gate, path, g.enabled, no_window, g.false_alarm);
    if (gate.contains("max_share")) {
      g.max_share = c.number(gate.at("max_share"), child(path, "max_share"));
      c.require(*g.max_share > 0.0 && *g.max_share < 1.0, child(path, "max_share"),
                "must be a share of the points in (0, 1)");
    }
  }
  c.require(!s.observations.observed.empty() || s.observations.surface_cloud, "filter",
            "the filter needs observations, and observations has no nodes, points or surface_cloud");
  s.filter = std::move(spec);
}

void read_effects(const Checker& c, const json& root, Scenario& s) {
  if (!root.contains("effects")) return;
  const json& effects = c.array(root.at("effects"), "effects");
  for (size_t i = 0; i < effects.size(); ++i) {
    const std::string path = element("effects", i);
    c.check_object(effects[i], path, {"name", "value"}, {"name", "value"});
    EffectValue effect;
    effect.name = c.string(effects[i].at("name"), child(path, "name"));
    const EffectDefinition* definition = find_effect(effect.name);
    c.require(definition != nullptr, child(path, "name"),
              "unknown effect " + in_quotes(effect.name) + "; known: " + effect_names());
    const json& value = effects[i].at("value");
    if (value.is_array()) {
      for (size_t k = 0; k < value.size(); ++k)
        effect.value.push_back(c.number(value[k], element(child(path, "value"), k)));
    } else {
      effect.value.push_back(c.number(value, child(path, "value")));
    }
    const std::string problem = effect_value_problem(*definition, effect.value);
    c.require(problem.empty(), child(path, "value"), effect.name + " " + problem);
    if (definition->regional) c.require(s.effect_region_problem(effect.name).empty(), child(path, "name"), s.effect_region_problem(effect.name));
    s.effects.push_back(std::move(effect));
  }
}

void read_output(const Checker& c, const json& root, Scenario& s) {
  if (!root.contains("output")) return;
  const json& output = root.at("output");
  c.check_object(output, "output", {"vtk_every"}, {});
  s.output.vtk_every = c.integer_or(output, "output", "vtk_every", s.output.vtk_every);
  c.require(s.output.vtk_every >= 0, "output.vtk_every",
            "must be >= 0 (0: no VTK frames), found " + std::to_string(s.output.vtk_every));
}

}  // namespace

Scenario load_scenario(const std::string& path) {
  const Checker c(path);
  const json root = c.parse(read_input_file(path, "scenario " + path, kMaxJsonBytes));
  c.require(root.is_object(), "(top level)",
            "expected a JSON object {...}, found " + describe(root));

  Scenario s;
  s.path = path;
  // The format first: a file of another format or version would otherwise be reported as
  // a list of unknown fields.
  c.require(root.contains("format"), "format",
            "missing required field; a scenario starts with \"format\": \"" + std::string(kFormat) +
                "\"");
  s.format = c.string(root.at("format"), "format");
  c.require(s.format == kFormat, "format",
            "this program reads " + in_quotes(kFormat) + ", found " + in_quotes(s.format));
  c.check_object(root, "",
                 {"format", "name", "description", "mesh", "material", "damping", "gravity", "time",
                  "solver", "ligaments", "regions", "candidate_regions", "control", "events", "observations",
                  "filter", "output", "effects"},
                 {"format", "mesh", "material", "time", "control"});

  s.name =
      root.contains("name") ? c.string(root.at("name"), "name") : fs::path(path).stem().string();
  c.require(!s.name.empty(), "name", "empty; leave the field out to use the file name");
  c.require(is_file_name_safe(s.name), root.contains("name") ? "name" : "name (from the file name)",
            quote_for_message(s.name) + " cannot name output files (" + kFileNameRule +
                ")" + (root.contains("name") ? "" : "; give a \"name\" field"));
  if (root.contains("description")) s.description = c.string(root.at("description"), "description");

  read_mesh_section(c, root, path, s);
  read_physics(c, root, s);
  read_ligaments(c, root, s);
  read_regions(c, root, s);
  read_control(c, root, path, s);
  read_candidate_regions(c, root, s);
  read_events(c, root, s);
  read_observations(c, root, s);
  read_filter(c, root, s);
  read_output(c, root, s);
  read_effects(c, root, s);
  return s;
}

}  // namespace sigmafem
