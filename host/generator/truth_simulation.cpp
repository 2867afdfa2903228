#include "host/generator/truth_simulation.h"

#include <cmath>
#include <numeric>
#include <stdexcept>

#include "host/common/input_error.h"
#include "host/engine/make_ensemble.h"

namespace sigmafem {

TruthSimulation::TruthSimulation(Model model, const GenerateOptions& options)
    : model_(std::move(model)) {
  for (const SpringSet& ligament : model_.ligaments) stiffness_.push_back(ligament.stiffness);
  if (options.backend == "cpu") {
    reference_.emplace(model_);
    if (options.device.preconditioner != Preconditioner::jacobi) {
      factor_ = std::make_unique<FactorisedPreconditioner>();
      reference_->set_preconditioner(factor_.get(), true);
    }
    return;
  }
  std::vector<int> all(model_.ligaments.size());
  std::iota(all.begin(), all.end(), 0);
  std::unique_ptr<Ensemble> ensemble = make_ensemble(options.backend, model_, all, {}, 1, options.device);
  device_.reset(dynamic_cast<DeviceEnsemble*>(ensemble.release()));
  if (!device_) throw InputError("--backend " + options.backend + ": not a device back end");
  positions_ = device_->positions(0);
}

void TruthSimulation::set_ligament_stiffness(const std::vector<double>& stiffness) {
  stiffness_ = stiffness;
  if (reference_) {
    reference_->set_ligament_stiffness(stiffness);
    return;
  }
  // Parameters are log-stiffness; a stiffness of exactly zero (log = -inf) gives exp = 0.
  Eigen::MatrixXd theta(static_cast<Eigen::Index>(stiffness.size()), 1);
  for (std::size_t l = 0; l < stiffness.size(); ++l)
    theta(static_cast<Eigen::Index>(l), 0) = std::log(stiffness[l]);
  device_->set_parameters(theta);
}

CgResult TruthSimulation::step(const Eigen::Vector3d& so_position) {
  if (reference_) return reference_->step(so_position);
  const StepReport report = device_->advance(so_position);
  CgResult result;
  result.iterations = report.cg_iterations[0];
  result.relative_residual = report.relative_residual[0];
  // The device's stop test |r|^2 <= tol^2 |b|^2 passes when |b| overflows: not a solve.
  result.converged = report.converged[0] != 0 && std::isfinite(result.relative_residual);
  positions_ = device_->positions(0);
  if (!positions_.allFinite())
    throw std::runtime_error("positions became non-finite on " + device_->description());
  return result;
}

Eigen::VectorXd TruthSimulation::positions() const {
  return reference_ ? reference_->positions() : positions_;
}

}  // namespace sigmafem
