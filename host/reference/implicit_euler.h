// ImplicitEulerSystem: the linear system of one linearised implicit Euler step
// (ARCHITECTURE.md; Baraff and Witkin 1998):
//   (M + h B + h^2 K) dv = h (f(x_n) - B v_n - h K v_n),   B = a K + b M,
// i.e. A = (1 + h b) M + h (h + a) K. K is the tangent stiffness: the elastic R K_e R^T of
// every element plus each spring's stiffness on its nodes' diagonal; a and b are the Rayleigh
// coefficients rayleigh_stiffness and rayleigh_mass. A is symmetric positive definite.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <vector>

#include "host/model/model.h"
#include "host/reference/assembly_pattern.h"
#include "host/reference/corotational.h"

namespace sigmafem {

class ImplicitEulerSystem {
 public:
  // `frames` are the element frames at x_n; `node_springs` is the per-node spring
  // stiffness (N/m, isotropic). Both are referenced, not copied: keep them alive.
  ImplicitEulerSystem(const Model& model, const std::vector<Frame>& frames,
                      const Eigen::VectorXd& node_springs);

  // y = K d (tangent stiffness, springs included).
  void stiffness_product(const Eigen::VectorXd& d, Eigen::VectorXd& y) const;
  // y = A d.
  void apply(const Eigen::VectorXd& d, Eigen::VectorXd& y) const;
  void operator()(const Eigen::VectorXd& d, Eigen::VectorXd& y) const { apply(d, y); }
  // diag(A).
  Eigen::VectorXd diagonal() const;
  // A assembled with the pattern's sparsity (built once per mesh), for the factors and the
  // direct solve.
  Eigen::SparseMatrix<double> assemble(const AssemblyPattern& pattern) const;
  // The right-hand side h (f - (h + a) K v - b M v) for the force f at x_n and velocity v.
  Eigen::VectorXd right_hand_side(const Eigen::VectorXd& force,
                                  const Eigen::VectorXd& velocity) const;

  double mass_factor() const { return mass_factor_; }
  double stiffness_factor() const { return stiffness_factor_; }

 private:
  const Model& model_;
  const std::vector<Frame>& frames_;
  const Eigen::VectorXd& node_springs_;
  Eigen::VectorXd dof_mass_;          // lumped mass repeated on the three axes
  Eigen::VectorXd dof_spring_;        // spring stiffness repeated on the three axes
  double mass_factor_;                // 1 + h b
  double stiffness_factor_;           // h (h + a)
};

}  // namespace sigmafem
