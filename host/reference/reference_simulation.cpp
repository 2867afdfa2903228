#include "host/reference/reference_simulation.h"

#include <Eigen/SparseCholesky>
#include <cmath>
#include <stdexcept>
#include <string>

#include "host/reference/factorised_preconditioner.h"
#include "host/reference/implicit_euler.h"

namespace sigmafem {

ReferenceSimulation::ReferenceSimulation(Model model)
    : model_(std::move(model)), so_history_(model_.control_start, model_.dt) {
  for (const SpringSet& ligament : model_.ligaments)
    ligament_stiffness_.push_back(ligament.stiffness);
  const int n = model_.node_count();
  x_.resize(3 * n);
  for (int i = 0; i < n; ++i) x_.segment<3>(3 * i) = model_.rest_positions[i];
  v_ = Eigen::VectorXd::Zero(3 * n);
  dv_ = Eigen::VectorXd::Zero(3 * n);
  base_gravity_ = model_.gravity;
  base_damping_ = model_.damping;
  base_d0_ = model_.ligament_d0;
  base_so_lag_ = model_.so_lag;
  base_control_scale_ = model_.control_scale;
  for (const ElementRest& element : model_.elements) base_lame_.emplace_back(element.vlambda, element.vmu);
  element_region_.assign(model_.elements.size(), -1);
  for (std::size_t r = 0; r < model_.regions.size(); ++r)
    for (int e : model_.regions[r].elements) element_region_.at(static_cast<std::size_t>(e)) = static_cast<int>(r);
  region_scale_.assign(model_.regions.size(), 1.0);
}

void ReferenceSimulation::update_element_moduli() {
  // Scaled from the model's values each time, so that no rounding accumulates over steps.
  for (std::size_t e = 0; e < model_.elements.size(); ++e) {
    const int r = element_region_[e];
    const double scale = young_scale_ * (r < 0 ? 1.0 : region_scale_[static_cast<std::size_t>(r)]);
    model_.elements[e].vlambda = scale * lambda_scale_ * base_lame_[e][0];
    model_.elements[e].vmu = scale * base_lame_[e][1];
  }
}

void ReferenceSimulation::set_region_young_modulus(const std::vector<double>& modulus) {
  if (modulus.size() != model_.regions.size())
    throw std::invalid_argument("set_region_young_modulus: expected " + std::to_string(model_.regions.size()) +
                                " values, got " + std::to_string(modulus.size()));
  bool changed = false;
  for (std::size_t r = 0; r < modulus.size(); ++r) {
    const double scale = modulus[r] / model_.regions[r].young_modulus;
    changed = changed || scale != region_scale_[r];
    region_scale_[r] = scale;
  }
  if (changed) update_element_moduli();
}

void ReferenceSimulation::set_physics_effects(const PhysicsEffects& effects) {
  model_.gravity = base_gravity_ + effects.gravity;
  model_.damping.rayleigh_mass = effects.damping_mass_scale * base_damping_.rayleigh_mass;
  model_.damping.rayleigh_stiffness = effects.damping_stiffness_scale * base_damping_.rayleigh_stiffness;
  model_.ligament_d0 = std::isfinite(effects.ligament_d0) ? effects.ligament_d0 : base_d0_;
  model_.so_lag = base_so_lag_ + effects.time_lag;
  model_.control_scale = base_control_scale_ * effects.control_scale;
  if (effects.young_scale == young_scale_ && effects.lambda_scale == lambda_scale_) return;
  young_scale_ = effects.young_scale;
  lambda_scale_ = effects.lambda_scale;
  update_element_moduli();
}

void ReferenceSimulation::set_ligament_stiffness(const std::vector<double>& stiffness) {
  if (stiffness.size() != model_.ligaments.size())
    throw std::invalid_argument("set_ligament_stiffness: expected " +
                                std::to_string(model_.ligaments.size()) + " values, got " +
                                std::to_string(stiffness.size()));
  ligament_stiffness_ = stiffness;
}

void ReferenceSimulation::set_state(const Eigen::VectorXd& positions,
                                    const Eigen::VectorXd& velocities) {
  if (positions.size() != x_.size() || velocities.size() != v_.size())
    throw std::invalid_argument("set_state: wrong vector size");
  x_ = positions;
  v_ = velocities;
}

Eigen::VectorXd ReferenceSimulation::node_springs() const {
  Eigen::VectorXd k = Eigen::VectorXd::Zero(model_.node_count());
  for (std::size_t l = 0; l < model_.ligaments.size(); ++l) {
    const SpringSet& ligament = model_.ligaments[l];
    for (std::size_t j = 0; j < ligament.nodes.size(); ++j)
      k[ligament.nodes[j]] += ligament.node_part(j, ligament_stiffness_[l]);
  }
  const SpringSet& control = model_.control;
  for (std::size_t j = 0; j < control.nodes.size(); ++j) k[control.nodes[j]] += control.node_part(j, control.stiffness);
  return k;
}

Eigen::VectorXd ReferenceSimulation::forces(const Eigen::VectorXd& x,
                                            const std::vector<Frame>& frames,
                                            const Eigen::Vector3d& so_position) const {
  Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
  add_element_forces(model_, frames, x, f);
  for (std::size_t l = 0; l < model_.ligaments.size(); ++l) {
    const SpringSet& ligament = model_.ligaments[l];
    for (std::size_t j = 0; j < ligament.nodes.size(); ++j) {
      const int node = ligament.nodes[j];
      const double k = ligament.node_part(j, ligament_stiffness_[l]);
      const Eigen::Vector3d u = x.segment<3>(3 * node) - model_.rest_positions[node];
      // The ligament law: k u (1 + |u|^2/d0^2); 1/d0^2 = 0 for the linear law (infinite d0).
      const double inverse_d0_squared = 1.0 / (model_.ligament_d0 * model_.ligament_d0);
      f.segment<3>(3 * node) -= k * (1.0 + u.squaredNorm() * inverse_d0_squared) * u;
    }
  }
  const SpringSet& control = model_.control;
  const Eigen::Vector3d shift = model_.control_scale * (so_position - model_.control_start);
  for (std::size_t j = 0; j < control.nodes.size(); ++j) {
    const int node = control.nodes[j];
    f.segment<3>(3 * node) -=
        control.node_part(j, control.stiffness) * (x.segment<3>(3 * node) - (model_.rest_positions[node] + shift));
  }
  if (!model_.gravity.isZero()) {
    for (int i = 0; i < model_.node_count(); ++i)
      f.segment<3>(3 * i) += model_.mass[i] * model_.gravity;
  }
  return f;
}

CgResult ReferenceSimulation::step(const Eigen::Vector3d& so_position) {
  so_history_.push(so_position);
  const Eigen::Vector3d so_target = so_history_.lagged(model_.so_lag);
  element_frames(model_, x_, frames_);
  const Eigen::VectorXd springs = node_springs();
  const ImplicitEulerSystem system(model_, frames_, springs);
  const Eigen::VectorXd b = system.right_hand_side(forces(x_, frames_, so_target), v_);

  CgResult result;
  const bool factored = solver_ == LinearSolver::conjugate_gradient && factor_ != nullptr;
  // A factor that cannot be made (not positive definite: a candidate's negative stiffness)
  // leaves this step to Jacobi; the next one tries again.
  if (factored && refresh_factor_ && factor_->due()) factor_->factorise(system.assemble(assembly_pattern()));
  if (factored && factor_->ready()) {
    result = preconditioned_conjugate_gradient(system, *factor_, b, dv_,
                                               model_.solver.cg_max_iterations,
                                               model_.solver.cg_tolerance);
  } else if (solver_ == LinearSolver::conjugate_gradient) {
    const Eigen::VectorXd inverse_diagonal = system.diagonal().cwiseInverse();
    result = conjugate_gradient(system, inverse_diagonal, b, dv_, model_.solver.cg_max_iterations,
                                model_.solver.cg_tolerance);
  } else {
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(system.assemble(assembly_pattern()));
    if (ldlt.info() != Eigen::Success)
      throw std::runtime_error("direct solve: the implicit Euler matrix is not positive definite");
    dv_ = ldlt.solve(b);
    Eigen::VectorXd Adv;
    system.apply(dv_, Adv);
    const double b_norm = b.norm();
    result.relative_residual = b_norm > 0.0 ? (Adv - b).norm() / b_norm : 0.0;
    result.converged = true;
  }
  if (factored && refresh_factor_) factor_->record(result.iterations);
  v_ += dv_;
  x_ += model_.dt * v_;
  if (!x_.allFinite() || !v_.allFinite())
    throw std::runtime_error("simulation step: positions or velocities became non-finite");
  return result;
}

Eigen::SparseMatrix<double> ReferenceSimulation::system_matrix() const {
  std::vector<Frame> frames;
  element_frames(model_, x_, frames);
  return ImplicitEulerSystem(model_, frames, node_springs()).assemble(assembly_pattern());
}

const AssemblyPattern& ReferenceSimulation::assembly_pattern() const {
  if (!assembly_pattern_) assembly_pattern_ = std::make_shared<const AssemblyPattern>(model_);
  return *assembly_pattern_;
}

double ReferenceSimulation::kinetic_energy() const {
  double e = 0.0;
  for (int i = 0; i < model_.node_count(); ++i)
    e += 0.5 * model_.mass[i] * v_.segment<3>(3 * i).squaredNorm();
  return e;
}

}  // namespace sigmafem
