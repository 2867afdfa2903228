// CpuEnsemble: the Ensemble (filter/ensemble.h) on the CPU reference: one ReferenceSimulation
// per sigma point, in double precision. It is the back end the device ensembles are checked
// against, and the one that runs anywhere. Sigma points are independent, so they run on
// worker threads kept for the ensemble's life (host/common/worker_pool.h: one per core, at
// most S, the caller's included); each one's arithmetic is unchanged by that, so
// results do not depend on the thread count.
//
// CG's preconditioner (host/common/device_options.h): Jacobi, as the lone ReferenceSimulation,
// or sparse Cholesky factors (factorised_preconditioner.h): one per sigma point, each made
// from its own system and again when it stops paying, while the S of them fit in
// kOwnFactorsBytes (cpu_ensemble.cpp); else one that all share, of the representative
// system (the sigma points' mean parameters at their mean state, as OpenCL's shared factor),
// made again between steps. The choice is made at the first step, from the size of sigma
// point 0's factor. Either way the results do not depend on the thread count; they differ
// from Jacobi's within the CG tolerance.
//
// Parameters (host/model/estimated_parameters.h): theta = log of the stiffness of the
// estimated ligaments, then log of the estimated regions' Young's modulus; the others keep
// the model's values.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <vector>

#include "host/common/device_options.h"
#include "host/common/worker_pool.h"
#include "host/ensemble/simulation_ensemble.h"
#include "host/mesh/observed_points.h"
#include "host/model/estimated_parameters.h"
#include "host/model/model.h"
#include "host/reference/factorised_preconditioner.h"
#include "host/reference/reference_simulation.h"

namespace sigmafem {

class CpuEnsemble : public SimulationEnsemble {
 public:
  // `estimated`: the ligaments and regions theta holds; `observed`: the observed points (node indices
  // convert); `threads` 0 = cores.
  // Preconditioner::automatic is the factors; the conformance tests, which compare the
  // devices' Jacobi CG with it to the last digits, ask for Jacobi.
  CpuEnsemble(const Model& model, EstimatedParameters estimated, ObservedPoints observed,
              int sigma_count, int threads = 0,
              Preconditioner preconditioner = Preconditioner::automatic);

  int sigma_count() const override { return static_cast<int>(simulations_.size()); }
  int parameter_count() const override { return estimated_.count(); }
  int observation_count() const override { return 3 * static_cast<int>(observed_.size()); }
  void set_parameters(const Eigen::MatrixXd& theta) override;
  StepReport advance(const Eigen::Vector3d& so_position) override;
  void predicted_observations(Eigen::MatrixXd& y) const override;
  void recenter(const Recentering& recentering) override;
  void read_states(Eigen::MatrixXd& positions, Eigen::MatrixXd& velocities) const override;
  void write_states(const Eigen::MatrixXd& positions, const Eigen::MatrixXd& velocities) override;

  void set_physics_effects(const std::vector<PhysicsEffects>& effects) override;

  // Factorisations made so far (0 with Jacobi), and whether the sigma points share one.
  int factorisations() const;
  bool shares_a_factor() const { return shared_factor_; }
  // The most the own factors may hold together before the sigma points share one instead
  // (default kOwnFactorsBytes); before the first step. Tests and benchmarks set it to run both.
  void set_own_factors_budget(double bytes) { own_factors_budget_ = bytes; }

  // Sigma point s's simulation (tests compare it with a lone ReferenceSimulation).
  const ReferenceSimulation& simulation(int s) const { return simulations_[s]; }

 private:
  std::vector<ReferenceSimulation> simulations_;
  EstimatedParameters estimated_;
  ObservedPoints observed_;
  std::unique_ptr<WorkerPool> pool_;   // the threads asked (0: the cores), at most S
  Preconditioner preconditioner_;
  // Empty with Jacobi and before the first step; then one per sigma point, or one shared.
  // The simulations hold pointers to them: unique_ptrs, so that moving the ensemble does
  // not move them.
  std::vector<std::unique_ptr<FactorisedPreconditioner>> factors_;
  bool shared_factor_ = false;
  double own_factors_budget_;
  Eigen::VectorXd mean_theta_;   // the sigma points' mean parameters (none yet: the model's)
  void make_factors();
  // What a shared factor is made of: the sigma points' mean parameters at their mean state.
  // Sigma point 0's own system was used until stop 48: a simplex point lies sqrt(p) prior
  // stds from the mean along one parameter, and over MPI ranks (p = 32 box regions on the 38k
  // liver) the rank whose first point held a region at 0.4% of the mean's modulus ran many
  // times the others' CG iterations (bench/RESULTS.md, stop 48).
  Eigen::SparseMatrix<double> representative_system() const;
};

}  // namespace sigmafem
