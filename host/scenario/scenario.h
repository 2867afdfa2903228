// Scenario: one experiment as described by a scenario JSON file (docs/FORMATS.md, format
// "sigmafem-scenario/1"): the organ mesh, its material, what holds it (ligaments), what
// moves it (the control spring to the solid object, SO), events, what is observed, and
// what the filter estimates. load_scenario() parses, checks every field, loads the mesh and
// resolves node selections to indices; after it returns, everything here is valid.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "host/mesh/mesh.h"
#include "host/mesh/observed_points.h"
#include "host/scenario/effect_catalogue.h"

namespace sigmafem {

struct MeshSpec {
  std::string file;                 // as written in the scenario
  std::string resolved_path;        // relative to the scenario's folder
  double scale = 1.0;
  Eigen::Vector3d translate = Eigen::Vector3d::Zero();
  int refine = 0;                   // uniform refinement levels (0..3), each x8 tetrahedra
};

// How each tetrahedron's rotation is taken from its corners (kernels/shared/element.h).
enum class ElementRotation {
  qr,      // SOFA's "large" method: a frame built on edge 0-1 and face 0-1-2 (the default)
  polar,   // SOFA's "polar" method: the rotation of the polar decomposition of the element's
           // deformation gradient; stable at large strain near nu = 0.5 (README, "The Truth Cube")
};

struct Material {
  double young_modulus = 0.0;       // Pa
  double poisson_ratio = 0.0;       // in (-1, 0.5)
  double density = 0.0;             // kg/m^3
  ElementRotation rotation = ElementRotation::qr;
};

struct Damping {
  double rayleigh_stiffness = 0.0;  // a in B = a K + b M (s)
  double rayleigh_mass = 0.0;       // b (1/s)
};

struct TimeSpec {
  double dt = 0.0;                  // s, > 0
  int steps = 0;                    // number of time steps, >= 1
};

struct SolverSpec {
  int cg_max_iterations = 1000;
  double cg_tolerance = 1e-10;      // relative residual |Ax - b| / |b|
};

// How a node set was written (docs/FORMATS.md `nodes` or `select`; candidate regions also
// `automatic`), kept so that the set can be resolved again on another mesh of the same organ
// (generate --truth-mesh, host/scenario/scenario_on_mesh.h). For `nodes` the list is the
// resolved set itself.
struct NodeSetSpec {
  enum class Kind { nodes, near, box, automatic };
  Kind kind = Kind::nodes;
  std::string field;                // where it was written, e.g. `ligaments[1] "middle"`
  Eigen::Vector3d near = Eigen::Vector3d::Zero();   // near: centre, metres
  double radius = 0.0;                              // near
  Eigen::Vector3d min = Eigen::Vector3d::Zero();    // box: corners, metres
  Eigen::Vector3d max = Eigen::Vector3d::Zero();
};

struct Ligament {
  std::string name;
  std::vector<int> nodes;           // resolved, sorted, unique
  double stiffness = 0.0;           // N/m, total: each node gets stiffness / nodes.size()
  // How `nodes` was written. Last, with "= {}", so that {name, nodes, stiffness} still
  // initialises a Ligament (tests, regions built in code) without a missing-field warning.
  NodeSetSpec selection = {};
};

// A part of the organ with a Young's modulus of its own (a tumour is stiffer; issue 19), which
// the filter may estimate (filter.estimate_young_modulus). Its elements are those whose rest
// centroid lies in the selection (near + radius, or box), or those the mesh file labels
// `label` (a Gmsh physical group); `selection` and `label` keep how it was written, so that
// scenario_on_mesh can select again on another mesh (region_elements).
struct Region {
  std::string name;
  std::vector<int> elements;        // sorted, unique, never empty
  double young_modulus = 0.0;       // Pa: the truth's (generate) and the model's until estimated
  NodeSetSpec selection = {};
  std::optional<int> label;         // set: by label, `selection` unused but for its field
};

// The SO trajectory so(t). so(0) is the centroid of the control nodes' rest positions.
struct Trajectory {
  enum class Type { linear, waypoints, file };
  Type type = Type::linear;
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();     // linear
  std::vector<double> times;                              // waypoints and file, increasing
  std::vector<Eigen::Vector3d> positions;                 // waypoints and file
  std::string file;                                       // file: as written
  // Position of the SO at time t; `start` is so(0) (used by `linear`). Waypoints are
  // piecewise linear, held constant before the first and after the last.
  Eigen::Vector3d position(double t, const Eigen::Vector3d& start) const;
};

// Reads a trajectory CSV (docs/FORMATS.md): a header `time,x,y,z`, then one row per knot,
// times strictly increasing, positions absolute (metres); `#` lines and blank lines are
// skipped. Returns a Trajectory of type `file` with `file` = path. Throws InputError
// "trajectory CSV PATH line N: problem" on anything else.
Trajectory read_trajectory_csv(const std::string& path);

struct Control {
  std::vector<int> nodes;           // resolved, sorted, unique
  double stiffness = 0.0;           // N/m, total
  Trajectory trajectory;
  Eigen::Vector3d start = Eigen::Vector3d::Zero();        // so(0): centroid of rest positions
  NodeSetSpec selection = {};       // how `nodes` was written
};

// At `time`, ligament `ligament` (index into Scenario::ligaments) gets `stiffness`.
struct Event {
  double time = 0.0;
  int ligament = -1;
  std::string ligament_name;
  double stiffness = 0.0;
};

// observations.surface_cloud: the organ seen as a cloud of surface points per frame, with no
// identity from one frame to the next (a depth camera or a laser scanner; issue 15, item 2).
// `generate` samples the frames from the visible patch (docs/FORMATS.md, "Point clouds");
// `estimate` reads them and observes each point's distance to the model's whole surface
// (filter/point_cloud_observation.h).
struct SurfaceCloud {
  int points_per_frame = 300;                        // sampled per frame, before dropouts
  Eigen::Vector3d view_direction{0.0, 0.0, -1.0};    // unit, from the camera towards the organ
  // The visible patch: the surface triangles that face the camera (rest normal . view < 0)
  // and whose rest centroid lies in this share of the organ's depth along the view, from
  // the side nearest the camera.
  double coverage = 1.0 / 3.0;
};

struct Observations {
  std::vector<int> nodes;           // in scenario order (not sorted), unique
  std::vector<Eigen::Vector3d> points;   // m, in the mesh's frame at rest, as written
  // Every observed point: the nodes (each as itself), then the points located on the mesh.
  // Their order is the column order of observations.csv (pK_x, pK_y, pK_z).
  ObservedPoints observed;
  double noise_std = 0.0;           // m, >= 0, used by the generator
  // Set: the observations are surface point clouds (and `observed` is empty).
  std::optional<SurfaceCloud> surface_cloud;
};

// Where observed point p was written: "observations.nodes[3] (node 17)" or
// "observations.points[0]".
std::string observed_point_name(const Observations& observations, std::size_t p);

// filter.change_detection: settings of the filter's cut detector (filter/change_detector.h);
// a field left out keeps the detector's default.
struct ChangeDetectionSpec {
  std::optional<bool> enabled;
  std::optional<int> window;
  std::optional<double> false_alarm;
  std::optional<int> hold_off;
  std::optional<double> inflation_log_std;
  std::optional<int> max_catch_up;
};

// filter.adaptive_noise: the observation-noise scale under model error
// (filter/adaptive_noise.h); a field left out keeps the default.
struct AdaptiveNoiseSpec {
  std::optional<bool> enabled;
  std::optional<int> window;
  std::optional<double> false_alarm;
};

// filter.outlier_gate: leaves outlying points out of a step's correction
// (filter/outlier_gate.h); a field left out keeps the default (off).
struct OutlierGateSpec {
  std::optional<bool> enabled;
  std::optional<double> false_alarm;
  std::optional<double> max_share;
};

struct FilterSpec {
  std::vector<int> estimate;        // indices into Scenario::ligaments
  std::vector<double> initial_stiffness;   // median prior stiffness per estimated ligament
  // Ligaments whose every spring (node) the filter estimates on its own (indices into
  // Scenario::ligaments, none of them in `estimate`), after the ligaments, and the prior
  // median of each of their springs (N/m).
  std::vector<int> estimate_springs;
  std::vector<double> initial_spring_stiffness;
  // Regions whose Young's modulus the filter estimates (indices into Scenario::regions), after
  // the springs in the parameter vector, and their prior medians (Pa).
  std::vector<int> estimate_regions;
  std::vector<double> initial_young_modulus;
  double initial_log_std = 1.0;
  double parameter_drift_log_std = 0.0;
  double observation_std = 0.0;
  std::string sigma_points = "simplex";    // "simplex" or "star"
  ChangeDetectionSpec change_detection;
  AdaptiveNoiseSpec adaptive_noise;
  OutlierGateSpec outlier_gate;
};

struct OutputSpec {
  int vtk_every = 10;               // write a VTK frame every k steps (0: none)
};

struct Scenario {
  std::string path;                 // the scenario file
  std::string format;
  std::string name;
  std::string description;          // free text, optional
  MeshSpec mesh_spec;
  Mesh mesh;                        // loaded, transformed to metres, oriented, checked, refined
  MeshQualityReport mesh_report;
  Material material;
  Damping damping;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  TimeSpec time;
  SolverSpec solver;
  std::vector<Ligament> ligaments;
  // Surface regions where `diagnose` tries an unmodelled ligament (extra_ligament:NAME); the
  // stiffness field is unused.
  std::vector<Ligament> candidate_regions;
  // Parts with their own Young's modulus (`regions`); the other elements have the material's.
  std::vector<Region> regions;
  Control control;
  std::vector<Event> events;        // sorted by time
  Observations observations;
  std::optional<FilterSpec> filter;
  OutputSpec output;
  // Effects declared part of the model (docs/FORMATS.md `effects`; host/model/effects.h):
  // generate simulates them, estimate and diagnose model them, with these fixed values.
  std::vector<EffectValue> effects;

  // Index of the ligament called `name`, or -1.
  int ligament_index(const std::string& name) const;
  // The ligaments' names, in order.
  std::vector<std::string> ligament_names() const;
  // The columns of generate's truth.csv: the ligaments' names, then "LIGAMENT@NODE" for each
  // spring the filter estimates on its own, then "E:REGION" per region.
  std::vector<std::string> truth_names() const;
  // Index of the candidate region called `name`, or -1.
  int candidate_region_index(const std::string& name) const;
  // Index of the region (`regions`) called `name`, or -1.
  int region_index(const std::string& name) const;
  // The names of the estimated parameters, in the filter's order: the ligaments', then
  // "LIGAMENT@NODE" for each spring of estimate_springs, then "E:REGION" for each estimated
  // Young's modulus (the columns of estimates.csv and truth.csv).
  std::vector<std::string> parameter_names() const;
  // "" when the region of a regional effect (FAMILY:REGION) is one of candidate_regions,
  // else what is wrong, naming the regions there are.
  std::string effect_region_problem(const std::string& effect_name) const;
  // Stiffness of every ligament in effect at time t: events with time <= t + 1e-9 applied,
  // in time order (the slack absorbs rounding when t is computed as step * dt).
  std::vector<double> ligament_stiffness_at(double t) const;
};

// Node selection (docs/FORMATS.md `select`), in the mesh's current frame (metres once
// transformed). Both are inclusive with a slack of kSelectionSlack, so that a node placed
// exactly on the sphere or the box face is caught despite rounding in scale/translate.
// Return sorted indices; empty when nothing matches.
constexpr double kSelectionSlack = 1e-9;  // m
std::vector<int> select_nodes_near(const Mesh& mesh, const Eigen::Vector3d& near, double radius);
std::vector<int> select_nodes_in_box(const Mesh& mesh, const Eigen::Vector3d& min,
                                     const Eigen::Vector3d& max);
// The tetrahedra whose centroid a `near` or `box` selection holds (regions), sorted.
std::vector<int> select_elements(const Mesh& mesh, const NodeSetSpec& selection);
// A region's tetrahedra on `mesh`: by its label (none when the mesh has no labels) or by
// its selection.
std::vector<int> region_elements(const Mesh& mesh, const Region& region);
// The name of node `node`'s spring of ligament `ligament` as a parameter: "LIGAMENT@NODE".
std::string spring_parameter_name(const std::string& ligament, int node);
// The name of region `name`'s Young's modulus as a parameter: "E:NAME"; and whether a
// parameter's name is one (a modulus in Pa, not a stiffness in N/m).
std::string young_modulus_parameter_name(const std::string& region_name);
bool is_young_modulus_parameter_name(const std::string& name);

// Reads and checks a scenario file. Throws InputError with "scenario FILE: FIELD: problem"
// for an unknown field, a wrong type, a missing file, a ligament or node index that does not
// exist, an empty node set, a non-positive dt, and every other invalid value.
Scenario load_scenario(const std::string& path);

}  // namespace sigmafem
