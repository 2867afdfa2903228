// The rigid fit recovers a known small motion, splits a field orthogonally into rigid part and
// remainder, skips missing rows, and gives the minimum-norm motion for collinear points.
#include "filter/rigid_fit.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

namespace sigmafem {
namespace {

Eigen::MatrixX3d box_points() {
  Eigen::MatrixX3d p(6, 3);
  p << 0.0, 0.0, 0.15,  0.3, 0.0, 0.15,  0.3, 0.15, 0.15,
       0.0, 0.15, 0.15, 0.15, 0.075, 0.0, 0.1, 0.02, 0.08;
  return p;
}

Eigen::VectorXd motion_field(const Eigen::MatrixX3d& p, const Eigen::Vector3d& c,
                             const Eigen::Vector3d& t, const Eigen::Vector3d& omega) {
  Eigen::VectorXd field(3 * p.rows());
  for (Eigen::Index j = 0; j < p.rows(); ++j)
    field.segment<3>(3 * j) = t + omega.cross(p.row(j).transpose() - c);
  return field;
}

TEST(RigidFit, RecoversATranslationAndARotation) {
  const Eigen::MatrixX3d p = box_points();
  const Eigen::Vector3d c = p.colwise().mean().transpose();
  const Eigen::Vector3d t(1e-3, -2e-3, 0.5e-3), omega(0.01, -0.02, 0.005);
  const RigidFit fit = fit_rigid_motion(p, c, motion_field(p, c, t, omega));
  EXPECT_LT((fit.translation - t).norm(), 1e-12) << "translation";
  EXPECT_LT((fit.rotation - omega).norm(), 1e-12) << "rotation";
  EXPECT_LT(fit.remainder.cwiseAbs().maxCoeff(), 1e-12) << "a rigid field leaves nothing";
}

TEST(RigidFit, SplitsAFieldOrthogonallyAndSkipsMissingRows) {
  const Eigen::MatrixX3d p = box_points();
  const Eigen::Vector3d c = p.colwise().mean().transpose();
  Eigen::VectorXd deformation(18);
  for (Eigen::Index i = 0; i < 18; ++i) deformation[i] = 1e-4 * std::sin(1.7 * static_cast<double>(i));
  Eigen::VectorXd field = motion_field(p, c, Eigen::Vector3d(2e-3, 0, 0), Eigen::Vector3d::Zero()) + deformation;
  field[4] = NAN;
  const RigidFit fit = fit_rigid_motion(p, c, field);
  EXPECT_TRUE(std::isnan(fit.rigid[4]) && std::isnan(fit.remainder[4])) << "the missing row stays missing";
  double field2 = 0, rigid2 = 0, rest2 = 0;
  for (Eigen::Index i = 0; i < 18; ++i) {
    if (i == 4) continue;
    field2 += field[i] * field[i];
    rigid2 += fit.rigid[i] * fit.rigid[i];
    rest2 += fit.remainder[i] * fit.remainder[i];
    EXPECT_NEAR(fit.rigid[i] + fit.remainder[i], field[i], 1e-15);
  }
  EXPECT_NEAR(rigid2 + rest2, field2, 1e-12 * field2) << "least squares: the parts are orthogonal";
  EXPECT_NEAR(fit.translation.x(), 2e-3, 2e-4) << "the translation dominates";
}

TEST(RigidFit, CollinearPointsGiveTheSmallestMotion) {
  Eigen::MatrixX3d p(3, 3);
  p << 0, 0, 0, 0.1, 0, 0, 0.2, 0, 0;   // on the x axis: a rotation about x moves nothing
  const Eigen::Vector3d c(0.1, 0, 0);
  const RigidFit fit = fit_rigid_motion(p, c, motion_field(p, c, Eigen::Vector3d(0, 1e-3, 0),
                                                           Eigen::Vector3d(0.3, 0, 0.01)));
  EXPECT_NEAR(fit.rotation.x(), 0.0, 1e-12) << "unobservable: reported as zero";
  EXPECT_NEAR(fit.rotation.z(), 0.01, 1e-12);
  EXPECT_NEAR(fit.translation.y(), 1e-3, 1e-12);
}

}  // namespace
}  // namespace sigmafem
