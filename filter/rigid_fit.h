// RigidFit: the rigid motion (a translation and a small rotation) that best explains a
// displacement-like field over the observed points in the least-squares sense,
//   d_j ~ t + omega x (p_j - c),   c = the centroid the rotation is taken about,
// and what is left over. The residual diagnostics use it to split the mean innovation into a
// rigid part (what a camera registration error would leave) and the rest (deformation the
// model does not produce). Small angles: omega is a rotation vector in radians, valid while
// |omega| << 1, as a registration error of a few millimetres over decimetres is.
#pragma once

#include <Eigen/Core>

namespace sigmafem {

struct RigidFit {
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();   // t, in the units of the field
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();      // omega, rad
  Eigen::VectorXd rigid;      // 3m: t + omega x (p_j - c) on the rows that were given (NaN elsewhere)
  Eigen::VectorXd remainder;  // 3m: field - rigid (NaN where the field is)
};

// `positions` (m x 3) are the observed points, `centroid` the centre of rotation, `field`
// (3m, point j's axis a at row 3j + a) the field, NaN = missing. Rows that are missing are
// left out of the fit. When the points do not fix all six components (fewer than three
// points, or all on a line) the fit is the smallest motion that explains the field equally
// well (minimum norm), so a rotation about the line of collinear points is reported as zero.
RigidFit fit_rigid_motion(const Eigen::MatrixX3d& positions, const Eigen::Vector3d& centroid,
                          const Eigen::VectorXd& field);

// The 3m x 6 matrix of the fit: row 3j + a maps (t, omega) to axis a of point j's motion.
Eigen::MatrixXd rigid_motion_basis(const Eigen::MatrixX3d& positions, const Eigen::Vector3d& centroid);

}  // namespace sigmafem
