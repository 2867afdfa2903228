// The shared element math (kernels/shared/element.h, in double through host/model) against
// the explicit rest stiffness K_e = V B^T D B of host/model (element_rest_stiffness): the
// factored product, force and diagonal are the matrices the design notes define
// (ARCHITECTURE.md, "The physics"), for random elements in random rotations.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <random>

#include "host/model/model.h"
#include "host/model/shared_element.h"
#include "tests/reference/structured_mesh.h"

namespace sigmafem {
namespace {

using Matrix12 = Eigen::Matrix<double, 12, 12>;
using Vector12 = Eigen::Matrix<double, 12, 1>;

// The factored and the explicit K_e are two roundings of the same matrix; both are formed
// from an inverse Jacobian of a reasonably shaped tetrahedron (condition number < ~30), so
// they agree to a few hundred ulps of the matrix's norm. 1e-12 leaves room without hiding
// a wrong term (any formula error is O(1) relative).
constexpr double kMatrixTolerance = 1e-12;
// K_e's asymmetry: only the rounding of the B^T D B product, a few ulps of its norm.
constexpr double kSymmetryTolerance = 1e-14;
// Force at the rest shape (moved rigidly): exactly zero in exact arithmetic; the rounding of
// positions of size ~1 m (translation) against an element of size ~0.1 m leaves ~1e-15 m of
// apparent displacement, i.e. a force ~1e-14 of the norm of K_e times the element size.
constexpr double kRestForceTolerance = 1e-12;
// Rotations from the frame: orthonormal to rounding.
constexpr double kRotationTolerance = 1e-13;

constexpr int kElements = 50;
constexpr Material kMaterial{3000.0, 0.45, 1000.0};   // soft tissue: E 3 kPa, nearly incompressible

// A random tetrahedron of size ~0.1 m near the origin, positively oriented and not too flat:
// the corners of a regular-ish tetrahedron moved by up to 30% of its edge.
std::array<double, 12> random_element(std::mt19937& random) {
  std::uniform_real_distribution<double> offset(-0.03, 0.03);
  const double base[12] = {0.0, 0.0, 0.0, 0.1, 0.0, 0.0, 0.05, 0.0866, 0.0, 0.05, 0.0289, 0.0816};
  const Eigen::Vector3d shift(offset(random) * 10.0, offset(random) * 10.0, offset(random) * 10.0);
  std::array<double, 12> corners{};
  for (int i = 0; i < 12; ++i) corners[i] = base[i] + offset(random) + shift[i % 3];
  return corners;
}

// A row-major frame[9] (element.h) as a matrix.
Eigen::Matrix3d frame_matrix(const double frame[9]) {
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(frame);
}

Eigen::Matrix3d frame_of(const std::array<double, 12>& corners) {
  double frame[9];
  shared::sf_element_frame(corners.data(), frame);
  return frame_matrix(frame);
}

double explicit_volume(const std::array<double, 12>& X) {
  const Eigen::Vector3d a(X[0], X[1], X[2]);
  const Eigen::Vector3d b = Eigen::Vector3d(X[3], X[4], X[5]) - a;
  const Eigen::Vector3d c = Eigen::Vector3d(X[6], X[7], X[8]) - a;
  const Eigen::Vector3d d = Eigen::Vector3d(X[9], X[10], X[11]) - a;
  return b.cross(c).dot(d) / 6.0;
}

// Q X + t for each corner.
std::array<double, 12> moved(const std::array<double, 12>& corners, const Eigen::Matrix3d& Q,
                             const Eigen::Vector3d& t) {
  std::array<double, 12> out{};
  for (int c = 0; c < 4; ++c) {
    const Eigen::Vector3d p =
        Q * Eigen::Vector3d(corners[3 * c], corners[3 * c + 1], corners[3 * c + 2]) + t;
    for (int k = 0; k < 3; ++k) out[3 * c + k] = p[k];
  }
  return out;
}

// The 12 x 12 matrix the factored product applies, column by column.
Matrix12 factored_matrix(const ElementRest& rest, const Eigen::Matrix3d& F) {
  double frame[9];
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) frame[3 * r + k] = F(r, k);
  Matrix12 K;
  for (int j = 0; j < 12; ++j) {
    double unit[12] = {0.0}, column[12];
    unit[j] = 1.0;
    shared::sf_element_product(frame, rest.grad.data(), rest.vlambda, rest.vmu, unit, column);
    for (int i = 0; i < 12; ++i) K(i, j) = column[i];
  }
  return K;
}

// blockdiag(Q, Q, Q, Q)
Matrix12 block_rotation(const Eigen::Matrix3d& Q) {
  Matrix12 R = Matrix12::Zero();
  for (int c = 0; c < 4; ++c) R.block<3, 3>(3 * c, 3 * c) = Q;
  return R;
}

class ElementTest : public ::testing::Test {
 protected:
  std::mt19937 random_{12345u};
};

TEST_F(ElementTest, ExplicitRestStiffnessIsSymmetricAndKillsRigidMotions) {
  for (int e = 0; e < kElements; ++e) {
    const std::array<double, 12> X = random_element(random_);
    const Matrix12 K = element_rest_stiffness(X, kMaterial);
    const double scale = K.norm();
    EXPECT_LE((K - K.transpose()).norm(), kSymmetryTolerance * scale)
        << "asymmetry of the explicit K_e of element " << e;
    // Translations and infinitesimal rotations (omega x X) are in the null space.
    for (int axis = 0; axis < 3; ++axis) {
      Vector12 translation = Vector12::Zero(), rotation;
      Eigen::Vector3d omega = Eigen::Vector3d::Zero();
      omega[axis] = 1.0;
      for (int c = 0; c < 4; ++c) {
        translation[3 * c + axis] = 1.0;
        rotation.segment<3>(3 * c) = omega.cross(Eigen::Vector3d(X[3 * c], X[3 * c + 1], X[3 * c + 2]));
      }
      EXPECT_LE((K * translation).norm(), kMatrixTolerance * scale * translation.norm())
          << "K_e times a translation along axis " << axis << ", element " << e;
      EXPECT_LE((K * rotation).norm(), kMatrixTolerance * scale * rotation.norm())
          << "K_e times an infinitesimal rotation about axis " << axis << ", element " << e;
    }
  }
}

TEST_F(ElementTest, FactoredProductEqualsRotatedExplicitStiffness) {
  for (int e = 0; e < kElements; ++e) {
    const std::array<double, 12> X = random_element(random_);
    const Matrix12 K_e = element_rest_stiffness(X, kMaterial);
    const ElementRest rest = element_rest_state(X, kMaterial);
    const Eigen::Matrix3d Q = test::random_rotation(random_);
    const Eigen::Vector3d t = test::random_vector(random_, 3);
    const std::array<double, 12> x = moved(X, Q, t);
    // The element frame of the rotated element; the product is R K_e' R^T with R = frame^T,
    // and must be Q K_e Q^T with K_e in world (rest) coordinates.
    const Eigen::Matrix3d F = frame_of(x);
    const Matrix12 expected = block_rotation(Q) * K_e * block_rotation(Q).transpose();
    const Matrix12 factored = factored_matrix(rest, F);
    const double scale = K_e.norm();
    EXPECT_LE((factored - expected).norm(), kMatrixTolerance * scale)
        << "factored product matrix vs Q K_e Q^T, element " << e;
    EXPECT_LE((factored - factored.transpose()).norm(), kMatrixTolerance * scale)
        << "asymmetry of the factored product matrix, element " << e;

    // And on a random vector directly (the way the kernels use it).
    const Vector12 d = test::random_vector(random_, 12);
    double frame[9], y[12];
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) frame[3 * r + k] = F(r, k);
    shared::sf_element_product(frame, rest.grad.data(), rest.vlambda, rest.vmu, d.data(), y);
    EXPECT_LE((Eigen::Map<const Vector12>(y) - expected * d).norm(),
              kMatrixTolerance * scale * d.norm())
        << "sf_element_product(d) vs Q K_e Q^T d, element " << e;

    // The volume is the explicit one, (X1 - X0) x (X2 - X0) . (X3 - X0) / 6.
    EXPECT_NEAR(rest.volume, explicit_volume(X), kMatrixTolerance * rest.volume)
        << "rest volume of element " << e;
  }
}

TEST_F(ElementTest, FrameIsARotationThatFollowsTheElement) {
  for (int e = 0; e < kElements; ++e) {
    const std::array<double, 12> X = random_element(random_);
    const Eigen::Matrix3d F0 = frame_of(X);
    EXPECT_LE((F0 * F0.transpose() - Eigen::Matrix3d::Identity()).norm(), kRotationTolerance)
        << "frame of element " << e << " is not orthonormal";
    EXPECT_NEAR(F0.determinant(), 1.0, kRotationTolerance)
        << "determinant of the frame of element " << e;
    const Eigen::Matrix3d Q = test::random_rotation(random_);
    // Rows are the axes in world coordinates, so rotating the element rotates each row by Q.
    EXPECT_LE((frame_of(moved(X, Q, Eigen::Vector3d(1.0, -2.0, 0.5))) - F0 * Q.transpose()).norm(),
              kRotationTolerance)
        << "frame of the rotated element " << e << " vs frame * Q^T";
  }
}

TEST_F(ElementTest, ForceVanishesOnTheRigidlyMovedRestShape) {
  for (int e = 0; e < kElements; ++e) {
    const std::array<double, 12> X = random_element(random_);
    const ElementRest rest = element_rest_state(X, kMaterial);
    const double scale = element_rest_stiffness(X, kMaterial).norm() * 0.1;   // |K_e| * size
    for (int motion = 0; motion < 2; ++motion) {
      const Eigen::Matrix3d Q = motion == 0 ? Eigen::Matrix3d::Identity() : test::random_rotation(random_);
      Eigen::Vector3d t = Eigen::Vector3d::Zero();
      if (motion == 1) t = test::random_vector(random_, 3);
      const std::array<double, 12> x = moved(X, Q, t);
      double frame[9], f[12];
      shared::sf_element_frame(x.data(), frame);
      shared::sf_element_force(frame, rest.grad.data(), rest.vlambda, rest.vmu, x.data(), f);
      EXPECT_LE(Eigen::Map<const Vector12>(f).norm(), kRestForceTolerance * scale)
          << "elastic force at the rest shape, element " << e
          << (motion == 0 ? " (in place)" : " (rigidly moved)");
    }
  }
}

TEST_F(ElementTest, ForceIsMinusRotatedStiffnessTimesCorotatedDisplacement) {
  // f = -R K_e (R^T x - X) up to a translation K_e ignores, with R the element rotation
  // (frame(x)^T frame(X)) and K_e explicit: the design notes' element force.
  for (int e = 0; e < kElements; ++e) {
    const std::array<double, 12> X = random_element(random_);
    const ElementRest rest = element_rest_state(X, kMaterial);
    const Matrix12 K_e = element_rest_stiffness(X, kMaterial);
    std::array<double, 12> deformed = X;
    std::uniform_real_distribution<double> strain(-0.01, 0.01);   // ~10% strain of a 0.1 m element
    for (double& v : deformed) v += strain(random_);
    const Eigen::Matrix3d Q = test::random_rotation(random_);
    const std::array<double, 12> x = moved(deformed, Q, test::random_vector(random_, 3));
    const Eigen::Matrix3d R = frame_of(x).transpose() * frame_of(X);
    const Vector12 xv = Eigen::Map<const Vector12>(x.data());
    const Vector12 Xv = Eigen::Map<const Vector12>(X.data());
    const Vector12 expected = -block_rotation(R) * K_e * (block_rotation(R).transpose() * xv - Xv);
    double frame[9], f[12];
    shared::sf_element_frame(x.data(), frame);
    shared::sf_element_force(frame, rest.grad.data(), rest.vlambda, rest.vmu, x.data(), f);
    const double displacement = (Eigen::Map<const Vector12>(deformed.data()) - Xv).norm();
    EXPECT_LE((Eigen::Map<const Vector12>(f) - expected).norm(),
              kMatrixTolerance * K_e.norm() * displacement)
        << "sf_element_force vs -R K_e (R^T x - X), element " << e;
  }
}

TEST_F(ElementTest, DiagonalEqualsDiagonalOfExplicitMatrix) {
  for (int e = 0; e < kElements; ++e) {
    const std::array<double, 12> X = random_element(random_);
    const ElementRest rest = element_rest_state(X, kMaterial);
    const Matrix12 K_e = element_rest_stiffness(X, kMaterial);
    const Eigen::Matrix3d Q = test::random_rotation(random_);
    const std::array<double, 12> x = moved(X, Q, test::random_vector(random_, 3));
    double frame[9], diag[12];
    shared::sf_element_frame(x.data(), frame);
    shared::sf_element_diagonal(frame, rest.grad.data(), rest.vlambda, rest.vmu, diag);
    const Vector12 expected = (block_rotation(Q) * K_e * block_rotation(Q).transpose()).diagonal();
    EXPECT_LE((Eigen::Map<const Vector12>(diag) - expected).norm(), kMatrixTolerance * K_e.norm())
        << "sf_element_diagonal vs diag(Q K_e Q^T), element " << e;
  }
}

// The polar frame (material.rotation "polar"): at rest and under rigid motion it is the QR
// frame (both are then the element's rotation); under any deformation it makes the stretch
// H = frame G symmetric, which is what gives forces without a net torque.
Eigen::Matrix3d polar_frame_of(const ElementRest& rest, const std::array<double, 12>& x) {
  double frame[9];
  shared::sf_element_polar_frame(rest.grad.data(), x.data(), frame);
  return frame_matrix(frame);
}

// x deformed by up to `strain` of the 0.1 m element per coordinate, then moved rigidly.
std::array<double, 12> deformed_and_moved(const std::array<double, 12>& X, double strain, std::mt19937& random) {
  std::uniform_real_distribution<double> offset(-strain * 0.1, strain * 0.1);
  std::array<double, 12> deformed = X;
  for (double& v : deformed) v += offset(random);
  return moved(deformed, test::random_rotation(random), test::random_vector(random, 3));
}

// The net torque sum_c x_c x f_c of the corner forces f at positions x.
Eigen::Vector3d net_torque(const std::array<double, 12>& x, const double f[12]) {
  Eigen::Vector3d torque = Eigen::Vector3d::Zero();
  for (int c = 0; c < 4; ++c)
    torque += Eigen::Vector3d(x[3 * c], x[3 * c + 1], x[3 * c + 2]).cross(Eigen::Vector3d(f[3 * c], f[3 * c + 1], f[3 * c + 2]));
  return torque;
}

TEST_F(ElementTest, PolarFrameIsTheQrFrameOfTheRigidlyMovedRestShape) {
  for (int e = 0; e < kElements; ++e) {
    const std::array<double, 12> X = random_element(random_);
    const ElementRest rest = element_rest_state(X, kMaterial);
    const Eigen::Matrix3d Q = test::random_rotation(random_);
    const std::array<double, 12> x = moved(X, Q, Eigen::Vector3d(1.0, -2.0, 0.5));
    EXPECT_LE((polar_frame_of(rest, x) - frame_of(x)).norm(), kRotationTolerance)
        << "polar vs QR frame of the rigidly moved rest shape, element " << e;
  }
}

TEST_F(ElementTest, PolarFrameMakesTheStretchSymmetricAtLargeStrain) {
  for (int e = 0; e < kElements; ++e) {
    const std::array<double, 12> X = random_element(random_);
    const ElementRest rest = element_rest_state(X, kMaterial);
    const std::array<double, 12> x = deformed_and_moved(X, 0.3, random_);   // strains up to ~50%
    const Eigen::Matrix3d F = polar_frame_of(rest, x);
    EXPECT_LE((F * F.transpose() - Eigen::Matrix3d::Identity()).norm(), kRotationTolerance) << "element " << e;
    EXPECT_NEAR(F.determinant(), 1.0, kRotationTolerance) << "element " << e;
    double G[9];
    shared::sf_element_gradient(rest.grad.data(), x.data(), 1.0, G);
    const Eigen::Matrix3d H = F * frame_matrix(G);   // G is row-major 3x3 too
    EXPECT_LE((H - H.transpose()).norm(), 1e-12 * H.norm()) << "stretch of element " << e;
    EXPECT_GT(H.eigenvalues().real().minCoeff(), 0.0) << "the stretch is positive definite, element " << e;
  }
}

// Angular momentum: the elastic forces of the polar frame have no net torque, at any strain
// (the stress H - I is symmetric in the frame); those of the QR frame do once the element is
// strained (its frame follows one edge, not the element), which is what drove the Truth
// Cube's drift at nu = 0.49 (README, "The Truth Cube"). Torques relative to |f| |x|.
TEST_F(ElementTest, PolarForcesHaveNoNetTorqueWhereQrForcesDo) {
  const Material incompressible{15300.0, 0.49, 1000.0};
  double largest_qr = 0.0;
  for (int e = 0; e < kElements; ++e) {
    const std::array<double, 12> X = random_element(random_);
    const ElementRest rest = element_rest_state(X, incompressible);
    const std::array<double, 12> x = deformed_and_moved(X, 0.2, random_);
    double frame[9], f[12];
    const auto relative_torque = [&]() {
      double size = 0.0;
      for (int i = 0; i < 12; ++i) size = std::max(size, std::abs(x[i]));
      return net_torque(x, f).norm() / (Eigen::Map<const Vector12>(f).norm() * size);
    };
    shared::sf_element_polar_frame(rest.grad.data(), x.data(), frame);
    shared::sf_element_force(frame, rest.grad.data(), rest.vlambda, rest.vmu, x.data(), f);
    EXPECT_LE(relative_torque(), 1e-12) << "net torque of the polar frame's forces, element " << e;
    shared::sf_element_frame(x.data(), frame);
    shared::sf_element_force(frame, rest.grad.data(), rest.vlambda, rest.vmu, x.data(), f);
    largest_qr = std::max(largest_qr, relative_torque());
  }
  EXPECT_GT(largest_qr, 1e-3) << "the QR frame's forces would have no net torque either: the test proves nothing";
}

TEST_F(ElementTest, AnInvertedElementKeepsTheQrFrame) {
  const std::array<double, 12> X = random_element(random_);
  const ElementRest rest = element_rest_state(X, kMaterial);
  std::array<double, 12> inverted = X;
  for (int k = 0; k < 3; ++k) inverted[9 + k] = X[k] - (X[9 + k] - X[k]);   // corner 3 through face 0-1-2's side
  EXPECT_EQ(polar_frame_of(rest, inverted), frame_of(inverted));
}

}  // namespace
}  // namespace sigmafem
