#include "filter/rigid_fit.h"

#include <Eigen/QR>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace sigmafem {

Eigen::MatrixXd rigid_motion_basis(const Eigen::MatrixX3d& positions, const Eigen::Vector3d& centroid) {
  const Eigen::Index m = positions.rows();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(3 * m, 6);
  for (Eigen::Index j = 0; j < m; ++j) {
    const Eigen::Vector3d r = positions.row(j).transpose() - centroid;
    A.block<3, 3>(3 * j, 0).setIdentity();
    // omega x r = -[r]_x omega.
    A.block<3, 3>(3 * j, 3) << 0.0, r.z(), -r.y(),
                               -r.z(), 0.0, r.x(),
                               r.y(), -r.x(), 0.0;
  }
  return A;
}

RigidFit fit_rigid_motion(const Eigen::MatrixX3d& positions, const Eigen::Vector3d& centroid,
                          const Eigen::VectorXd& field) {
  if (field.size() != 3 * positions.rows())
    throw std::invalid_argument("fit_rigid_motion: the field has " + std::to_string(field.size()) +
                                " rows for " + std::to_string(positions.rows()) + " points");
  const Eigen::MatrixXd A = rigid_motion_basis(positions, centroid);
  std::vector<Eigen::Index> rows;
  for (Eigen::Index i = 0; i < field.size(); ++i)
    if (!std::isnan(field[i])) rows.push_back(i);
  RigidFit fit;
  fit.rigid = Eigen::VectorXd::Constant(field.size(), NAN);
  fit.remainder = Eigen::VectorXd::Constant(field.size(), NAN);
  if (rows.empty()) return fit;
  Eigen::MatrixXd A_observed(static_cast<Eigen::Index>(rows.size()), 6);
  Eigen::VectorXd b(A_observed.rows());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    A_observed.row(static_cast<Eigen::Index>(k)) = A.row(rows[k]);
    b[static_cast<Eigen::Index>(k)] = field[rows[k]];
  }
  // Minimum-norm least squares: well defined for any geometry of the points.
  const Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(A_observed);
  const Eigen::VectorXd motion = cod.solve(b);
  fit.translation = motion.head<3>();
  fit.rotation = motion.tail<3>();
  const Eigen::VectorXd rigid = A_observed * motion;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    fit.rigid[rows[k]] = rigid[static_cast<Eigen::Index>(k)];
    fit.remainder[rows[k]] = field[rows[k]] - rigid[static_cast<Eigen::Index>(k)];
  }
  return fit;
}

}  // namespace sigmafem
