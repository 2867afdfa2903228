// Scenario queries that the generator and the filter ask during a run: which ligament has
// a name, what stiffness every ligament has at a given time once events are applied, and
// where an observed point was written.
#include "host/scenario/scenario.h"

namespace sigmafem {

namespace {
// Times in a run are computed as step * dt, which can land a hair below an event time
// written as a round number (750 * 0.01 = 7.4999999999999991); the slack keeps such an
// event on its intended step. 1e-9 s is far below any dt anyone will use.
constexpr double kEventTimeSlack = 1e-9;
}  // namespace

std::vector<std::string> Scenario::ligament_names() const {
  std::vector<std::string> names;
  for (const Ligament& ligament : ligaments) names.push_back(ligament.name);
  return names;
}

std::vector<std::string> Scenario::truth_names() const {
  std::vector<std::string> names = ligament_names();
  if (filter)
    for (int l : filter->estimate_springs)
      for (int node : ligaments[static_cast<size_t>(l)].nodes)
        names.push_back(spring_parameter_name(ligaments[static_cast<size_t>(l)].name, node));
  for (const Region& region : regions) names.push_back(young_modulus_parameter_name(region.name));
  return names;
}

int Scenario::ligament_index(const std::string& ligament_name) const {
  for (size_t i = 0; i < ligaments.size(); ++i) {
    if (ligaments[i].name == ligament_name) return static_cast<int>(i);
  }
  return -1;
}

int Scenario::candidate_region_index(const std::string& region_name) const {
  for (size_t i = 0; i < candidate_regions.size(); ++i)
    if (candidate_regions[i].name == region_name) return static_cast<int>(i);
  return -1;
}

int Scenario::region_index(const std::string& region_name) const {
  for (size_t i = 0; i < regions.size(); ++i)
    if (regions[i].name == region_name) return static_cast<int>(i);
  return -1;
}

std::string young_modulus_parameter_name(const std::string& region_name) { return "E:" + region_name; }

bool is_young_modulus_parameter_name(const std::string& name) { return name.rfind("E:", 0) == 0; }

std::string spring_parameter_name(const std::string& ligament, int node) {
  return ligament + "@" + std::to_string(node);
}

std::vector<std::string> Scenario::parameter_names() const {
  std::vector<std::string> names;
  if (!filter) return names;
  for (int l : filter->estimate) names.push_back(ligaments[static_cast<size_t>(l)].name);
  for (int l : filter->estimate_springs)
    for (int node : ligaments[static_cast<size_t>(l)].nodes)
      names.push_back(spring_parameter_name(ligaments[static_cast<size_t>(l)].name, node));
  for (int r : filter->estimate_regions) names.push_back(young_modulus_parameter_name(regions[static_cast<size_t>(r)].name));
  return names;
}

std::string Scenario::effect_region_problem(const std::string& effect_name) const {
  const std::string region = effect_region(effect_name);
  if (candidate_region_index(region) >= 0) return "";
  std::string names;
  for (const Ligament& r : candidate_regions) names += (names.empty() ? "" : ", ") + r.name;
  return "no candidate region \"" + region + "\" in scenario " + name +
         " (candidate_regions: " + (names.empty() ? "none declared" : names) + ")";
}

std::vector<double> Scenario::ligament_stiffness_at(double t) const {
  std::vector<double> stiffness;
  stiffness.reserve(ligaments.size());
  for (const Ligament& ligament : ligaments) stiffness.push_back(ligament.stiffness);
  // Events are sorted by time (stable, so equal times keep file order): the last one that
  // has happened for a ligament wins.
  for (const Event& event : events) {
    if (event.time > t + kEventTimeSlack) break;
    stiffness[static_cast<size_t>(event.ligament)] = event.stiffness;
  }
  return stiffness;
}

std::string observed_point_name(const Observations& observations, std::size_t p) {
  if (p < observations.nodes.size())
    return "observations.nodes[" + std::to_string(p) + "] (node " +
           std::to_string(observations.nodes[p]) + ")";
  return "observations.points[" + std::to_string(p - observations.nodes.size()) + "]";
}

}  // namespace sigmafem
