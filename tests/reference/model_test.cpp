// make_model and the rest state (host/model/model): lumped mass, volumes and Lame terms
// against hand formulas on a jittered box whose volume is known exactly.
#include "host/model/model.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "tests/reference/structured_mesh.h"

namespace sigmafem {
namespace {

// Sums of ~100 element volumes or masses against the box's exact volume: ~1e-15 relative.
constexpr double kSumTolerance = 1e-13;
// Closed-form Lame coefficients of simple numbers: exact to an ulp or two.
constexpr double kModelFormulaTolerance = 1e-15;

TEST(ModelTest, LameCoefficientsAreTheIsotropicFormulas) {
  // E = 1, nu = 0.25: lambda = E nu / ((1 + nu)(1 - 2 nu)) = 0.4, mu = E / (2 (1 + nu)) = 0.4.
  const Eigen::Vector2d lame = lame_coefficients(Material{1.0, 0.25, 1.0});
  EXPECT_NEAR(lame[0], 0.4, kModelFormulaTolerance) << "Lame lambda for E = 1, nu = 0.25";
  EXPECT_NEAR(lame[1], 0.4, kModelFormulaTolerance) << "shear modulus mu for E = 1, nu = 0.25";
  // nu = 0: no lateral coupling.
  const Eigen::Vector2d uncoupled = lame_coefficients(Material{3.0, 0.0, 1.0});
  EXPECT_EQ(uncoupled[0], 0.0) << "Lame lambda for nu = 0";
  EXPECT_NEAR(uncoupled[1], 1.5, kModelFormulaTolerance) << "shear modulus mu for E = 3, nu = 0";
}

TEST(ModelTest, MassIsLumpedAQuarterOfEachElementPerCorner) {
  const Eigen::Vector3d size(0.1, 0.06, 0.04);
  const test::StructuredBox box = test::structured_box(size, 5, 3, 2, 0.1);
  const Material material{3000.0, 0.45, 1000.0};
  const Model model = make_model(box.mesh, material);
  ASSERT_EQ(model.element_count(), box.mesh.tetrahedron_count()) << "element count";
  ASSERT_EQ(model.node_count(), box.mesh.node_count()) << "node count";
  const double box_volume = size.prod();
  const Eigen::Vector2d lame = lame_coefficients(material);
  Eigen::VectorXd expected_mass = Eigen::VectorXd::Zero(model.node_count());
  double volume = 0.0;
  for (int e = 0; e < model.element_count(); ++e) {
    const ElementRest& element = model.elements[e];
    const double V = test::signed_volume(box.mesh, box.mesh.tetrahedra[e]);
    EXPECT_EQ(element.nodes, box.mesh.tetrahedra[e]) << "nodes of element " << e;
    EXPECT_NEAR(element.volume, V, kSumTolerance * V) << "volume of element " << e;
    EXPECT_NEAR(element.vlambda, V * lame[0], kSumTolerance * V * lame[0]) << "V lambda of element " << e;
    EXPECT_NEAR(element.vmu, V * lame[1], kSumTolerance * V * lame[1]) << "V mu of element " << e;
    for (int node : element.nodes) expected_mass[node] += material.density * V / 4.0;
    volume += element.volume;
  }
  EXPECT_NEAR(volume, box_volume, kSumTolerance * box_volume) << "total element volume vs the box's";
  EXPECT_NEAR(model.mass.sum(), material.density * box_volume,
              kSumTolerance * material.density * box_volume)
      << "total lumped mass vs density times the box's volume";
  EXPECT_LE((model.mass - expected_mass).norm(), kSumTolerance * expected_mass.norm())
      << "lumped mass per node vs a quarter of each incident element's mass";
}

TEST(ModelTest, RestGradientsReproduceTheRestShape) {
  // Shape-function gradients in the element's rest frame: they sum to zero (constants have no
  // gradient) and sum_c X'_c grad_c^T = I for the corners X'_c in that frame (linear fields
  // are reproduced): the identity that sf_element_force subtracts as the rest shape.
  const test::StructuredBox box = test::structured_box(Eigen::Vector3d(0.3, 0.2, 0.2), 3, 2, 2, 0.1);
  const Model model = make_model(box.mesh, Material{3000.0, 0.45, 1000.0});
  for (int e = 0; e < model.element_count(); ++e) {
    const ElementRest& element = model.elements[e];
    // The rest frame: x along edge 0-1, z along the normal of face 0-1-2 (element.h).
    const Eigen::Vector3d X0 = model.rest_positions[element.nodes[0]];
    const Eigen::Vector3d ex = (model.rest_positions[element.nodes[1]] - X0).normalized();
    const Eigen::Vector3d ez =
        ex.cross(model.rest_positions[element.nodes[2]] - X0).normalized();
    Eigen::Matrix3d F;
    F.row(0) = ex;
    F.row(1) = ez.cross(ex);
    F.row(2) = ez;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d reproduced = Eigen::Matrix3d::Zero();
    for (int c = 0; c < 4; ++c) {
      const Eigen::Vector3d grad(element.grad[3 * c], element.grad[3 * c + 1], element.grad[3 * c + 2]);
      sum += grad;
      reproduced += (F * (model.rest_positions[element.nodes[c]] - X0)) * grad.transpose();
    }
    double grad_scale = 0.0;
    for (double g : element.grad) grad_scale = std::max(grad_scale, std::abs(g));
    EXPECT_LE(sum.norm(), kSumTolerance * grad_scale) << "sum of the gradients of element " << e;
    EXPECT_LE((reproduced - Eigen::Matrix3d::Identity()).norm(), kSumTolerance)
        << "sum_c X'_c grad_c^T vs I, element " << e;
  }
}

}  // namespace
}  // namespace sigmafem
