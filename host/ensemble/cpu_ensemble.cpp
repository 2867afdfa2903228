#include "host/ensemble/cpu_ensemble.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <thread>

#include "host/ensemble/threaded_resampling.h"

namespace sigmafem {
namespace {

// Own factors converge in about half the iterations of a shared one (bench/RESULTS.md) and
// suit diagnose, whose sigma points differ by whole effects, but they hold S factors: up to
// 1 GiB of them (S = 16 on a 4768-tetrahedron liver takes about 30 MB), one shared above.
constexpr double kOwnFactorsBytes = 1024.0 * 1024.0 * 1024.0;

}  // namespace

CpuEnsemble::CpuEnsemble(const Model& model, EstimatedParameters estimated, ObservedPoints observed,
                         int sigma_count, int threads, Preconditioner preconditioner)
    : estimated_(std::move(estimated)),
      observed_(std::move(observed)),
      preconditioner_(preconditioner),
      own_factors_budget_(kOwnFactorsBytes) {
  if (sigma_count < 1) throw std::invalid_argument("CpuEnsemble: need at least one sigma point");
  check_estimated_parameters(estimated_, model, "CpuEnsemble");
  check_observed_points(observed_, model.node_count(), "CpuEnsemble");
  ReferenceSimulation first(model);
  // One assembly pattern for all the factors' refreshes, not one per sigma point.
  if (preconditioner_ != Preconditioner::jacobi) first.assembly_pattern();
  simulations_.assign(sigma_count, first);
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  pool_ = std::make_unique<WorkerPool>(std::min(threads > 0 ? threads : std::max(1, cores), sigma_count));
}

void CpuEnsemble::make_factors() {
  auto first = std::make_unique<FactorisedPreconditioner>();
  first->factorise(simulations_[0].system_matrix());
  shared_factor_ = sigma_count() * first->bytes() > own_factors_budget_;
  factors_.push_back(std::move(first));
  if (shared_factor_) {
    if (sigma_count() > 1) factors_[0]->factorise(representative_system());
    for (ReferenceSimulation& simulation : simulations_)
      simulation.set_preconditioner(factors_[0].get(), false);
    return;
  }
  for (int s = 1; s < sigma_count(); ++s) factors_.push_back(std::make_unique<FactorisedPreconditioner>());
  for (int s = 0; s < sigma_count(); ++s) simulations_[s].set_preconditioner(factors_[s].get(), true);
}

int CpuEnsemble::factorisations() const {
  int count = 0;
  for (const auto& factor : factors_) count += factor->factorisations();
  return count;
}

Eigen::SparseMatrix<double> CpuEnsemble::representative_system() const {
  ReferenceSimulation representative = simulations_[0];
  if (mean_theta_.size() > 0) {
    std::vector<double> stiffness = representative.ligament_stiffness(), moduli;
    apply_parameters(representative.model(), estimated_, mean_theta_, stiffness, moduli);
    representative.set_ligament_stiffness(stiffness);
    representative.set_region_young_modulus(moduli);
  }
  Eigen::VectorXd x = Eigen::VectorXd::Zero(simulations_[0].positions().size());
  Eigen::VectorXd v = x;
  for (const ReferenceSimulation& simulation : simulations_) {
    x += simulation.positions();
    v += simulation.velocities();
  }
  representative.set_state(x / sigma_count(), v / sigma_count());
  return representative.system_matrix();
}

void CpuEnsemble::set_parameters(const Eigen::MatrixXd& theta) {
  check_parameter_matrix(theta, parameter_count(), sigma_count(), "CpuEnsemble");
  mean_theta_ = theta.rowwise().mean();
  for (int s = 0; s < sigma_count(); ++s) {
    std::vector<double> stiffness = simulations_[s].ligament_stiffness(), moduli;
    apply_parameters(simulations_[s].model(), estimated_, theta.col(s), stiffness, moduli);
    simulations_[s].set_ligament_stiffness(stiffness);
    simulations_[s].set_region_young_modulus(moduli);
  }
}

void CpuEnsemble::set_physics_effects(const std::vector<PhysicsEffects>& effects) {
  if (static_cast<int>(effects.size()) != sigma_count())
    throw std::invalid_argument("CpuEnsemble::set_physics_effects: expected one entry per sigma point");
  for (int s = 0; s < sigma_count(); ++s) simulations_[s].set_physics_effects(effects[s]);
}

StepReport CpuEnsemble::advance(const Eigen::Vector3d& so_position) {
  const int S = sigma_count();
  StepReport report;
  report.cg_iterations.resize(S);
  report.relative_residual.resize(S);
  report.converged.resize(S);
  const int factorisations_before = factorisations();
  if (preconditioner_ != Preconditioner::jacobi && factors_.empty()) make_factors();
  // A shared factor is made again here, between steps; own ones in each simulation's step.
  if (shared_factor_ && factors_[0]->due()) factors_[0]->factorise(representative_system());
  pool_->run(S, [&](int s) {
    const CgResult cg = simulations_[s].step(so_position);
    report.cg_iterations[s] = cg.iterations;
    report.relative_residual[s] = cg.relative_residual;
    report.converged[s] = cg.converged ? 1u : 0u;
  });
  if (shared_factor_)
    factors_[0]->record(*std::max_element(report.cg_iterations.begin(), report.cg_iterations.end()));
  report.factorisations = factorisations() - factorisations_before;
  return report;
}

void CpuEnsemble::predicted_observations(Eigen::MatrixXd& y) const {
  y.resize(observation_count(), sigma_count());
  for (int s = 0; s < sigma_count(); ++s)
    for (std::size_t k = 0; k < observed_.size(); ++k)
      y.block<3, 1>(3 * static_cast<Eigen::Index>(k), s) = observed_[k].of(simulations_[s].positions());
}

void CpuEnsemble::recenter(const Recentering& r) {
  Eigen::MatrixXd X, V;
  read_states(X, V);
  // docs/ROUKF.md steps 1-2 (filter/ensemble.h, resampled_states, by blocks of rows on the
  // ensemble's threads: host/ensemble/threaded_resampling.h): mean and factor of the
  // predicted states, the correction, then the new factor L C and the re-sampled states;
  // positions and velocities alike (the state of a dynamic simulation is both).
  write_states(resampled_states_on(*pool_, X, r), resampled_states_on(*pool_, V, r));
}

void CpuEnsemble::read_states(Eigen::MatrixXd& positions, Eigen::MatrixXd& velocities) const {
  const int S = sigma_count();
  const Eigen::Index n = simulations_[0].positions().size();
  positions.resize(n, S);
  velocities.resize(n, S);
  for (int s = 0; s < S; ++s) {
    positions.col(s) = simulations_[s].positions();
    velocities.col(s) = simulations_[s].velocities();
  }
}

void CpuEnsemble::write_states(const Eigen::MatrixXd& positions, const Eigen::MatrixXd& velocities) {
  check_state_matrices(positions, velocities, simulations_[0].positions().size(), sigma_count(), "CpuEnsemble");
  for (int s = 0; s < sigma_count(); ++s) simulations_[s].set_state(positions.col(s), velocities.col(s));
}

}  // namespace sigmafem
