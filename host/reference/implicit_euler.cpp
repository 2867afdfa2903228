#include "host/reference/implicit_euler.h"

namespace sigmafem {

ImplicitEulerSystem::ImplicitEulerSystem(const Model& model, const std::vector<Frame>& frames,
                                         const Eigen::VectorXd& node_springs)
    : model_(model),
      frames_(frames),
      node_springs_(node_springs),
      mass_factor_(1.0 + model.dt * model.damping.rayleigh_mass),
      stiffness_factor_(model.dt * (model.dt + model.damping.rayleigh_stiffness)) {
  const int n = model.node_count();
  dof_mass_.resize(3 * n);
  dof_spring_.resize(3 * n);
  for (int i = 0; i < n; ++i) {
    // A node that no tetrahedron uses (mesh.h keeps them, so that indices stay the file's)
    // has no mass and, without a spring, no stiffness: its rows of A would be zero. A unit
    // placeholder mass makes them the identity; with no force on the node, dv = 0 and it
    // stays where it is. Its real mass (zero) still counts everywhere else.
    const bool isolated = model.mass[i] == 0.0 && node_springs_[i] == 0.0;
    dof_mass_.segment<3>(3 * i).setConstant(isolated ? 1.0 : model.mass[i]);
    dof_spring_.segment<3>(3 * i).setConstant(node_springs_[i]);
  }
}

void ImplicitEulerSystem::stiffness_product(const Eigen::VectorXd& d, Eigen::VectorXd& y) const {
  element_product(model_, frames_, d, y);
  y += dof_spring_.cwiseProduct(d);
}

void ImplicitEulerSystem::apply(const Eigen::VectorXd& d, Eigen::VectorXd& y) const {
  stiffness_product(d, y);
  y *= stiffness_factor_;
  y += mass_factor_ * dof_mass_.cwiseProduct(d);
}

Eigen::VectorXd ImplicitEulerSystem::diagonal() const {
  Eigen::VectorXd diag;
  element_diagonal(model_, frames_, diag);
  return mass_factor_ * dof_mass_ + stiffness_factor_ * (diag + dof_spring_);
}

Eigen::SparseMatrix<double> ImplicitEulerSystem::assemble(const AssemblyPattern& pattern) const {
  Eigen::SparseMatrix<double> A = assemble_element_stiffness(model_, frames_, pattern);
  double* values = A.valuePtr();
  for (Eigen::Index k = 0; k < A.nonZeros(); ++k) values[k] *= stiffness_factor_;
  const Eigen::VectorXd extra = mass_factor_ * dof_mass_ + stiffness_factor_ * dof_spring_;
  for (int i = 0; i < A.rows(); ++i) values[pattern.diagonal_slot(i)] += extra[i];
  return A;
}

Eigen::VectorXd ImplicitEulerSystem::right_hand_side(const Eigen::VectorXd& force,
                                                     const Eigen::VectorXd& velocity) const {
  const double h = model_.dt;
  Eigen::VectorXd Kv;
  stiffness_product(velocity, Kv);
  return h * (force - (h + model_.damping.rayleigh_stiffness) * Kv -
              model_.damping.rayleigh_mass * dof_mass_.cwiseProduct(velocity));
}

}  // namespace sigmafem
