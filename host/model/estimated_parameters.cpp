#include "host/model/estimated_parameters.h"

#include <cmath>
#include <stdexcept>

namespace sigmafem {

EstimatedParameters estimated_parameters(const FilterSpec& spec, Model& model) {
  EstimatedParameters estimated(spec.estimate, spec.estimate_regions);
  for (int l : spec.estimate_springs) {
    const SpringSet whole = model.ligaments.at(static_cast<std::size_t>(l));   // a copy: the list grows
    for (std::size_t k = 0; k < whole.nodes.size(); ++k) {
      estimated.ligaments.push_back(static_cast<int>(model.ligaments.size()));
      model.ligaments.push_back({spring_parameter_name(whole.name, whole.nodes[k]), {whole.nodes[k]},
                                 whole.node_part(k, whole.stiffness), {}});
    }
    model.ligaments[static_cast<std::size_t>(l)].stiffness = 0.0;   // its springs hold its nodes now
  }
  return estimated;
}

void apply_parameters(const Model& model, const EstimatedParameters& estimated, const Eigen::VectorXd& theta,
                      std::vector<double>& stiffness, std::vector<double>& young_moduli) {
  for (std::size_t j = 0; j < estimated.ligaments.size(); ++j)
    stiffness.at(static_cast<std::size_t>(estimated.ligaments[j])) = std::exp(theta[static_cast<Eigen::Index>(j)]);
  young_moduli.clear();
  for (const ElasticRegion& region : model.regions) young_moduli.push_back(region.young_modulus);
  for (std::size_t k = 0; k < estimated.regions.size(); ++k)
    young_moduli[static_cast<std::size_t>(estimated.regions[k])] = std::exp(theta[estimated.region_row(k)]);
}

void check_estimated_parameters(const EstimatedParameters& estimated, const Model& model, const std::string& who) {
  for (int l : estimated.ligaments)
    if (l < 0 || l >= static_cast<int>(model.ligaments.size()))
      throw std::invalid_argument(who + ": no ligament " + std::to_string(l));
  for (int r : estimated.regions)
    if (r < 0 || r >= static_cast<int>(model.regions.size()))
      throw std::invalid_argument(who + ": no region " + std::to_string(r));
}

}  // namespace sigmafem
