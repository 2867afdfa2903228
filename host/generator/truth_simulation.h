// TruthSimulation: the one simulation that makes synthetic data, on the CPU reference or on
// a device back end (`sigmafem generate --backend opencl`): a device ensemble of one sigma
// point whose parameters are the log-stiffness of every ligament. Either way the generator
// sees the same three operations: set the stiffnesses, step, read the positions.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <vector>

#include "host/ensemble/device_ensemble.h"
#include "host/generator/generate.h"
#include "host/model/model.h"
#include "host/reference/factorised_preconditioner.h"
#include "host/reference/reference_simulation.h"

namespace sigmafem {

class TruthSimulation {
 public:
  // Throws InputError for an unknown back end, DeviceError when its device cannot run.
  TruthSimulation(Model model, const GenerateOptions& options);

  const Model& model() const { return model_; }
  void set_ligament_stiffness(const std::vector<double>& stiffness);
  const std::vector<double>& ligament_stiffness() const { return stiffness_; }
  // One step with the SO at `so_position`; the solver's work and status.
  CgResult step(const Eigen::Vector3d& so_position);
  Eigen::VectorXd positions() const;

 private:
  Model model_;
  std::vector<double> stiffness_;
  std::optional<ReferenceSimulation> reference_;    // the "cpu" back end
  std::unique_ptr<FactorisedPreconditioner> factor_;   // its preconditioner (null: Jacobi)
  std::unique_ptr<DeviceEnsemble> device_;          // any other
  Eigen::VectorXd positions_;                       // the device's, read back once per step
};

}  // namespace sigmafem
