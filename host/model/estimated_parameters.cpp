#include "host/model/estimated_parameters.h"

#include <stdexcept>

namespace sigmafem {

void check_estimated_parameters(const EstimatedParameters& estimated, const Model& model, const std::string& who) {
  for (int l : estimated.ligaments)
    if (l < 0 || l >= static_cast<int>(model.ligaments.size()))
      throw std::invalid_argument(who + ": no ligament " + std::to_string(l));
  for (int r : estimated.regions)
    if (r < 0 || r >= static_cast<int>(model.regions.size()))
      throw std::invalid_argument(who + ": no region " + std::to_string(r));
}

}  // namespace sigmafem
