// The co-rotational forces and tangent of a whole mesh (host/reference/corotational):
// rigid motions of the rest shape, however large the rotation, give no force and are seen as
// the element rotation; the tangent is the symmetric positive semi-definite stiffness of a
// free body (exactly six rigid-body zero modes) and the force's Jacobian at rest; the
// matrix-free product and diagonal are the assembled matrix's.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <random>
#include <vector>

#include "host/model/model.h"
#include "host/reference/corotational.h"
#include "tests/reference/structured_mesh.h"

namespace sigmafem {
namespace {

// Rigid motions: the force is zero in exact arithmetic. Rounding leaves an apparent strain of a
// few ulps in every element; with lambda ~3 E (nu = 0.45) and ~24 elements per node that is
// a nodal force ~1e-13 N, measured up to 3e-13 N, i.e. ~1e-11 of the force of a 1e-3 strain,
// E h^2 1e-3 = 0.03 N. 1e-10 of that scale leaves a factor ~10, while any real error (a wrong
// frame, a rest shape not subtracted) gives forces of order E h^2.
constexpr double kRigidForceTolerance = 1e-10;
// Element rotation vs the applied one: rotations built from unit vectors, ~10 ulps.
constexpr double kAssemblyRotationTolerance = 1e-12;
// The assembled tangent is a sum of element matrices, each symmetric to a few ulps of its norm.
constexpr double kAssemblySymmetryTolerance = 1e-13;
// Free-body spectrum (dense eigensolver, eigenvalues accurate to ~1e-15 of the largest):
// the six rigid-body modes are zero to rounding, far below 1e-9 of the largest eigenvalue;
// the softest elastic mode of this 3 x 2 x 2 box is 4e-3 of it (measured), far above 1e-4.
constexpr double kZeroEigenvalue = 1e-9;
constexpr double kFirstElasticEigenvalue = 1e-4;
// Matrix-free product and diagonal vs the assembled matrix: the same element products summed
// in a different order, ~1e-15 of the result.
constexpr double kProductTolerance = 1e-13;
// Central difference of the force vs the tangent at a (rotated) rest state. The tangent is the
// exact Jacobian there (the stress is zero, so the rotation's derivative does not contribute);
// the step leaves O(step^2) truncation, ~1e-12, and rounding of the positions, ~1e-16 m over a
// displacement of 1e-6 m, i.e. ~1e-10 of the force difference.
constexpr double kJacobianTolerance = 1e-7;
constexpr double kJacobianStep = 1e-6;   // m, displacement size of the difference
// Objectivity of a deformed state: f(Q x + t) = Q f(x); rounding of positions ~1 m against
// deformations of ~1e-3 m, i.e. ~1e-13 of the force.
constexpr double kObjectivityTolerance = 1e-10;

constexpr Material kTissue{3000.0, 0.45, 1000.0};   // soft tissue
constexpr double kCellSize = 0.1;                     // m

class CorotationalTest : public ::testing::Test {
 protected:
  CorotationalTest()
      : box_(test::structured_box(Eigen::Vector3d(3 * kCellSize, 2 * kCellSize, 2 * kCellSize), 3,
                                  2, 2, 0.1)),
        model_(make_model(box_.mesh, kTissue)),
        rest_(test::flat_positions(box_.mesh)) {}

  // The rigid motions tried: random ones and large explicit ones (90, 170, 180 degrees).
  std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>> rigid_motions() {
    std::vector<std::pair<Eigen::Matrix3d, Eigen::Vector3d>> motions;
    motions.emplace_back(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0.7, -1.0, 0.3));
    motions.emplace_back(test::rotation_about(Eigen::Vector3d(1.0, 2.0, 3.0), test::degrees(90.0)),
                         Eigen::Vector3d::Zero());
    motions.emplace_back(test::rotation_about(Eigen::Vector3d(-1.0, 0.5, 0.2), test::degrees(170.0)),
                         Eigen::Vector3d(0.1, 0.2, -0.5));
    motions.emplace_back(test::rotation_about(Eigen::Vector3d(0.3, -0.2, 1.0), test::degrees(180.0)),
                         Eigen::Vector3d(-0.4, 0.0, 0.9));
    for (int i = 0; i < 6; ++i)
      motions.emplace_back(test::random_rotation(random_), test::random_vector(random_, 3));
    return motions;
  }

  Eigen::VectorXd forces(const Eigen::VectorXd& x) const {
    std::vector<Frame> frames;
    element_frames(model_, x, frames);
    Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
    add_element_forces(model_, frames, x, f);
    return f;
  }

  Eigen::MatrixXd dense_tangent(const Eigen::VectorXd& x) const {
    std::vector<Frame> frames;
    element_frames(model_, x, frames);
    return Eigen::MatrixXd(assemble_element_stiffness(model_, frames));
  }

  std::mt19937 random_{2026u};
  test::StructuredBox box_;
  Model model_;
  Eigen::VectorXd rest_;
};

TEST_F(CorotationalTest, RigidMotionsGiveNoForceAndTheirRotation) {
  const double force_scale = kTissue.young_modulus * kCellSize * kCellSize * 1e-3;
  int motion_index = 0;
  for (const auto& [Q, t] : rigid_motions()) {
    const Eigen::VectorXd x = test::rigidly_moved(rest_, Q, t);
    std::vector<Frame> frames;
    element_frames(model_, x, frames);
    Eigen::VectorXd f = Eigen::VectorXd::Zero(x.size());
    add_element_forces(model_, frames, x, f);
    EXPECT_LE(f.lpNorm<Eigen::Infinity>(), kRigidForceTolerance * force_scale)
        << "largest nodal elastic force after rigid motion " << motion_index;
    double worst = 0.0;
    int worst_element = -1;
    for (int e = 0; e < model_.element_count(); ++e) {
      const double error = (element_rotation(model_, frames, e) - Q).norm();
      if (error > worst) {
        worst = error;
        worst_element = e;
      }
    }
    EXPECT_LE(worst, kAssemblyRotationTolerance)
        << "element rotation vs the applied rotation, element " << worst_element
        << ", rigid motion " << motion_index;
    ++motion_index;
  }
}

TEST_F(CorotationalTest, TangentOfAFreeBodyHasExactlySixZeroModes) {
  int motion_index = 0;
  for (const auto& [Q, t] : rigid_motions()) {
    const Eigen::MatrixXd K = dense_tangent(test::rigidly_moved(rest_, Q, t));
    const double scale = K.norm();
    EXPECT_LE((K - K.transpose()).norm(), kAssemblySymmetryTolerance * scale)
        << "asymmetry of the assembled tangent, rigid motion " << motion_index;
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eigen(0.5 * (K + K.transpose()),
                                                               Eigen::EigenvaluesOnly);
    const Eigen::VectorXd& lambda = eigen.eigenvalues();   // ascending
    const double largest = lambda[lambda.size() - 1];
    EXPECT_GE(lambda[0], -kZeroEigenvalue * largest)
        << "smallest eigenvalue of the tangent (positive semi-definite), rigid motion "
        << motion_index;
    for (int i = 0; i < 6; ++i)
      EXPECT_LE(std::abs(lambda[i]), kZeroEigenvalue * largest)
          << "rigid-body eigenvalue " << i << " of the tangent, rigid motion " << motion_index;
    EXPECT_GE(lambda[6], kFirstElasticEigenvalue * largest)
        << "seventh eigenvalue of the tangent (the softest elastic mode), rigid motion "
        << motion_index;
    ++motion_index;
  }
}

TEST_F(CorotationalTest, TangentIsTheForceJacobianAtRigidlyMovedRest) {
  int motion_index = 0;
  for (const auto& [Q, t] : rigid_motions()) {
    const Eigen::VectorXd x = test::rigidly_moved(rest_, Q, t);
    const Eigen::MatrixXd K = dense_tangent(x);
    const Eigen::VectorXd u = test::random_vector(random_, x.size(), kJacobianStep);
    const Eigen::VectorXd df = (forces(x + u) - forces(x - u)) / 2.0;
    const Eigen::VectorXd expected = -K * u;
    EXPECT_LE((df - expected).norm(), kJacobianTolerance * expected.norm())
        << "central difference of the force vs -K u, rigid motion " << motion_index;
    ++motion_index;
  }
}

TEST_F(CorotationalTest, MatrixFreeProductAndDiagonalEqualTheAssembledMatrix) {
  // A deformed, rotated state: 1% random strain of each node's cell and a large rotation. The
  // assembled blocks are written out from the product (element_stiffness_block), so this is
  // also the check of that formula, with either frame.
  const Eigen::VectorXd deformed = rest_ + test::random_vector(random_, rest_.size(), 1e-2 * kCellSize);
  const Eigen::VectorXd x = test::rigidly_moved(
      deformed, test::rotation_about(Eigen::Vector3d(1.0, 1.0, -2.0), 2.0), Eigen::Vector3d(0.2, 0.0, 0.1));
  for (ElementRotation rotation : {ElementRotation::qr, ElementRotation::polar}) {
    model_.material.rotation = rotation;
    const char* name = rotation == ElementRotation::qr ? "QR frames" : "polar frames";
    std::vector<Frame> frames;
    element_frames(model_, x, frames);
    const Eigen::SparseMatrix<double> K = assemble_element_stiffness(model_, frames);
    const Eigen::MatrixXd K_dense(K);
    EXPECT_LE((K_dense - K_dense.transpose()).norm(), kAssemblySymmetryTolerance * K_dense.norm())
        << "asymmetry of the assembled tangent of a deformed state, " << name;
    for (int trial = 0; trial < 3; ++trial) {
      const Eigen::VectorXd d = test::random_vector(random_, x.size());
      Eigen::VectorXd y;
      element_product(model_, frames, d, y);
      const Eigen::VectorXd expected = K * d;
      EXPECT_LE((y - expected).norm(), kProductTolerance * expected.norm())
          << "element_product vs the assembled tangent times a vector, trial " << trial << ", " << name;
    }
    Eigen::VectorXd diagonal;
    element_diagonal(model_, frames, diagonal);
    const Eigen::VectorXd expected_diagonal = K_dense.diagonal();
    EXPECT_LE((diagonal - expected_diagonal).norm(), kProductTolerance * expected_diagonal.norm())
        << "element_diagonal vs the assembled tangent's diagonal, " << name;
  }
}

TEST_F(CorotationalTest, ForceAndTangentAreObjective) {
  // A deformed state (strain ~1e-2) moved rigidly: the force turns with it, f(Q x + t) = Q f(x),
  // and the tangent is Q K Q^T; what a co-rotational formulation is for.
  const Eigen::VectorXd x = rest_ + test::random_vector(random_, rest_.size(), 1e-3);
  const Eigen::VectorXd f = forces(x);
  const Eigen::MatrixXd K = dense_tangent(x);
  int motion_index = 0;
  for (const auto& [Q, t] : rigid_motions()) {
    const Eigen::VectorXd x_moved = test::rigidly_moved(x, Q, t);
    const Eigen::VectorXd expected_f = test::rigidly_moved(f, Q, Eigen::Vector3d::Zero());
    EXPECT_LE((forces(x_moved) - expected_f).norm(), kObjectivityTolerance * f.norm())
        << "force of the rigidly moved deformed state vs the rotated force, rigid motion "
        << motion_index;
    Eigen::MatrixXd blocks = Eigen::MatrixXd::Zero(K.rows(), K.cols());
    for (Eigen::Index n = 0; n < K.rows() / 3; ++n) blocks.block<3, 3>(3 * n, 3 * n) = Q;
    const Eigen::MatrixXd QKQ = blocks * K * blocks.transpose();
    EXPECT_LE((dense_tangent(x_moved) - QKQ).norm(), kObjectivityTolerance * K.norm())
        << "tangent of the rigidly moved deformed state vs Q K Q^T, rigid motion " << motion_index;
    ++motion_index;
  }
}

}  // namespace
}  // namespace sigmafem
