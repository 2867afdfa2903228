// ReferenceSimulation: one organ simulated on the CPU in double precision, step by step.
// This is the oracle every device back end is tested against (ARCHITECTURE.md). One step:
//   1. element frames at x_n (rotations),
//   2. forces f(x_n): elastic, ligament springs to rest (linear, or the law of
//      Model::ligament_d0), control spring to the SO target at the END of the step
//      (so(t_{n+1}); sigmafem's convention; so(t_{n+1} - so_lag) with a lag), gravity,
//   3. solve (M + h B + h^2 K) dv = h (f - B v - h K v) by Jacobi-preconditioned CG
//      warm-started from the last dv (or by a sparse direct solve, to check CG; or by CG
//      preconditioned by a sparse Cholesky factor instead: factorised_preconditioner.h),
//   4. v += dv, x += h v.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <memory>
#include <vector>

#include "host/model/effects.h"
#include "host/model/model.h"
#include "host/model/so_history.h"
#include "host/reference/assembly_pattern.h"
#include "host/reference/conjugate_gradient.h"
#include "host/reference/corotational.h"

namespace sigmafem {

class FactorisedPreconditioner;

enum class LinearSolver { conjugate_gradient, direct };

class ReferenceSimulation {
 public:
  // Starts at rest: x = rest positions, v = 0, ligament stiffnesses those of the model.
  explicit ReferenceSimulation(Model model);

  const Model& model() const { return model_; }

  // Stiffness (N/m, total) of each ligament, in model.ligaments order.
  void set_ligament_stiffness(const std::vector<double>& stiffness);
  const std::vector<double>& ligament_stiffness() const { return ligament_stiffness_; }

  void set_linear_solver(LinearSolver solver) { solver_ = solver; }
  // CG preconditioned by `factor` (not owned; it must outlive the steps) instead of Jacobi
  // while factor->ready(); nullptr restores Jacobi. `refresh`: the step makes the factor
  // again from its own system when it is due (the simulation's own factor); false: the
  // caller does (a factor an ensemble shares between its simulations).
  void set_preconditioner(FactorisedPreconditioner* factor, bool refresh) {
    factor_ = factor;
    refresh_factor_ = refresh;
  }
  // The matrix the next step solves with, at the current state (CpuEnsemble factorises one).
  Eigen::SparseMatrix<double> system_matrix() const;
  // The sparsity its assembly fills, made at the first assembly; copies of the simulation
  // share it (CpuEnsemble makes it once, before copying the simulation per sigma point).
  const AssemblyPattern& assembly_pattern() const;

  // Young's modulus (Pa) of each of the model's regions (Model::regions, in order); their
  // model values restore.
  void set_region_young_modulus(const std::vector<double>& modulus);

  // Physics effects on top of the model given at construction (diagnose estimates them per
  // sigma point); PhysicsEffects{} restores the model.
  void set_physics_effects(const PhysicsEffects& effects);

  // Advances one time step with the SO at `so_position` (the SO at the end of the step).
  // Throws std::runtime_error if the state becomes non-finite.
  CgResult step(const Eigen::Vector3d& so_position);

  const Eigen::VectorXd& positions() const { return x_; }
  const Eigen::VectorXd& velocities() const { return v_; }
  void set_state(const Eigen::VectorXd& positions, const Eigen::VectorXd& velocities);
  Eigen::Vector3d node_position(int node) const { return x_.segment<3>(3 * node); }

  // The spring stiffness on each node (ligaments and control), N/m: the linear law's. With
  // a nonlinear ligament law the implicit step takes the law's linear part implicitly and the
  // rest, k u |u|^2/d0^2, explicitly in the forces (as the device kernels do).
  Eigen::VectorXd node_springs() const;
  // All forces at positions x with the SO at so_position, for the frames of x.
  Eigen::VectorXd forces(const Eigen::VectorXd& x, const std::vector<Frame>& frames,
                         const Eigen::Vector3d& so_position) const;
  double kinetic_energy() const;

 private:
  Model model_;
  std::vector<double> ligament_stiffness_;
  LinearSolver solver_ = LinearSolver::conjugate_gradient;
  FactorisedPreconditioner* factor_ = nullptr;
  bool refresh_factor_ = false;
  mutable std::shared_ptr<const AssemblyPattern> assembly_pattern_;   // null until needed
  Eigen::VectorXd x_, v_;
  Eigen::VectorXd dv_;                 // last velocity change: the CG warm start
  std::vector<Frame> frames_;
  Eigen::Vector3d base_gravity_;
  // The elements' Lame terms are the model's scaled by the young_scale and lambda_scale
  // effects and by their region's modulus over its model value (update_element_moduli).
  std::vector<Eigen::Vector2d> base_lame_;   // per element: vlambda, vmu of the model
  std::vector<int> element_region_;          // per element: index into model.regions, or -1
  std::vector<double> region_scale_;         // per region
  double young_scale_ = 1.0, lambda_scale_ = 1.0;
  void update_element_moduli();
  Damping base_damping_;
  double base_d0_ = 0.0, base_so_lag_ = 0.0, base_control_scale_ = 1.0;
  SoHistory so_history_;                     // for the lag (Model::so_lag)
};

}  // namespace sigmafem
