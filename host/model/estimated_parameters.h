// EstimatedParameters: which of a model's quantities an ensemble's parameter vector theta holds,
// in its row order: the log-stiffness (N/m) of each listed ligament (a whole ligament, or one
// spring of one split per spring), then the log of each listed region's Young's modulus (Pa;
// Model::regions, issue 19). The filter's algebra sees p
// numbers and knows nothing of which is which.
#pragma once

#include <Eigen/Core>
#include <initializer_list>
#include <string>
#include <vector>

#include "host/model/model.h"

namespace sigmafem {

struct EstimatedParameters {
  std::vector<int> ligaments;   // indices into Model::ligaments
  std::vector<int> regions;     // indices into Model::regions

  EstimatedParameters() = default;
  // Ligaments only (what every ensemble estimated before regions): a list converts.
  EstimatedParameters(std::vector<int> ligament_indices, std::vector<int> region_indices = {})
      : ligaments(std::move(ligament_indices)), regions(std::move(region_indices)) {}
  EstimatedParameters(std::initializer_list<int> ligament_indices) : ligaments(ligament_indices) {}

  int count() const { return static_cast<int>(ligaments.size() + regions.size()); }
  // Row of region list entry k in theta.
  int region_row(std::size_t k) const { return static_cast<int>(ligaments.size() + k); }
};

// What a scenario's filter block estimates, in Scenario::parameter_names' order: the
// ligaments of spec.estimate, then each spring of spec.estimate_springs, then the regions.
// Each ligament estimated per spring is split in `model` (made from that scenario): a
// ligament of one node per spring ("LIGAMENT@NODE", its part of the stiffness) is appended,
// and the whole one keeps its nodes at zero stiffness.
EstimatedParameters estimated_parameters(const FilterSpec& spec, Model& model);

// One parameter vector `theta` (p) applied to all of `model`'s ligaments and regions: the
// estimated ones exp(theta), the others `stiffness` (as given) and the model's moduli (Pa).
void apply_parameters(const Model& model, const EstimatedParameters& estimated, const Eigen::VectorXd& theta,
                      std::vector<double>& stiffness, std::vector<double>& young_moduli);

// Throws std::invalid_argument naming `who` for an index `model` does not have.
void check_estimated_parameters(const EstimatedParameters& estimated, const Model& model, const std::string& who);

}  // namespace sigmafem
