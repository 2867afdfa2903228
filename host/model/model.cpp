#include "host/model/model.h"

#include <Eigen/Dense>
#include <cmath>

#include "host/model/effects.h"
#include "host/model/shared_element.h"

namespace sigmafem {
namespace {

// Shape-function gradients of a linear tetrahedron with these corners (rows = corners):
// with J = [X1 - X0, X2 - X0, X3 - X0] (columns), the gradients of N1..N3 are the rows of
// J^-1 and grad N0 = -(grad N1 + grad N2 + grad N3). Returns the signed volume det(J) / 6.
double shape_gradients(const std::array<double, 12>& corners, Eigen::Matrix<double, 4, 3>& grad) {
  Eigen::Matrix3d J;
  for (int c = 1; c < 4; ++c)
    for (int k = 0; k < 3; ++k) J(k, c - 1) = corners[3 * c + k] - corners[k];
  const Eigen::Matrix3d J_inv = J.inverse();
  grad.row(1) = J_inv.row(0);
  grad.row(2) = J_inv.row(1);
  grad.row(3) = J_inv.row(2);
  grad.row(0) = -(grad.row(1) + grad.row(2) + grad.row(3));
  return J.determinant() / 6.0;
}

}  // namespace

Eigen::Vector2d lame_coefficients(const Material& material) {
  const double E = material.young_modulus, nu = material.poisson_ratio;
  return {E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)), E / (2.0 * (1.0 + nu))};
}

ElementRest element_rest_state(const std::array<double, 12>& corners, const Material& material) {
  // Gradients with respect to the rest frame's coordinates: the frame the current rotation
  // is measured against (SOFA's rotatedInitialElements).
  double frame[9];
  shared::sf_element_frame(corners.data(), frame);
  std::array<double, 12> rest{};
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) rest[3 * c + r] += frame[3 * r + k] * (corners[3 * c + k] - corners[k]);
  Eigen::Matrix<double, 4, 3> grad;
  ElementRest element;
  element.volume = shape_gradients(rest, grad);
  for (int c = 0; c < 4; ++c)
    for (int j = 0; j < 3; ++j) element.grad[3 * c + j] = grad(c, j);
  const Eigen::Vector2d lame = lame_coefficients(material);
  element.vlambda = element.volume * lame[0];
  element.vmu = element.volume * lame[1];
  return element;
}

Eigen::Matrix<double, 12, 12> element_rest_stiffness(const std::array<double, 12>& corners,
                                                     const Material& material) {
  Eigen::Matrix<double, 4, 3> grad;
  const double volume = shape_gradients(corners, grad);
  // Strain-displacement matrix B (6 x 12), Voigt order xx yy zz xy yz zx, engineering shear.
  Eigen::Matrix<double, 6, 12> B = Eigen::Matrix<double, 6, 12>::Zero();
  for (int c = 0; c < 4; ++c) {
    const double gx = grad(c, 0), gy = grad(c, 1), gz = grad(c, 2);
    B(0, 3 * c) = gx;
    B(1, 3 * c + 1) = gy;
    B(2, 3 * c + 2) = gz;
    B(3, 3 * c) = gy;
    B(3, 3 * c + 1) = gx;
    B(4, 3 * c + 1) = gz;
    B(4, 3 * c + 2) = gy;
    B(5, 3 * c) = gz;
    B(5, 3 * c + 2) = gx;
  }
  const Eigen::Vector2d lame = lame_coefficients(material);
  Eigen::Matrix<double, 6, 6> D = Eigen::Matrix<double, 6, 6>::Zero();
  D.topLeftCorner<3, 3>().setConstant(lame[0]);
  D.topLeftCorner<3, 3>().diagonal().array() += 2.0 * lame[1];
  D.bottomRightCorner<3, 3>().diagonal().setConstant(lame[1]);
  return volume * B.transpose() * D * B;
}

Model make_model(const Mesh& mesh, const Material& material) {
  Model model;
  model.material = material;
  model.rest_positions = mesh.nodes;
  model.mass = Eigen::VectorXd::Zero(mesh.node_count());
  model.elements.reserve(mesh.tetrahedra.size());
  for (const auto& tet : mesh.tetrahedra) {
    std::array<double, 12> corners{};
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 3; ++k) corners[3 * c + k] = mesh.nodes[tet[c]][k];
    ElementRest element = element_rest_state(corners, material);
    element.nodes = tet;
    for (int c = 0; c < 4; ++c) model.mass[tet[c]] += material.density * element.volume / 4.0;
    model.elements.push_back(element);
  }
  return model;
}

Model make_model(const Scenario& scenario) {
  Model model = make_model(scenario.mesh, scenario.material);
  model.damping = scenario.damping;
  model.gravity = scenario.gravity;
  model.dt = scenario.time.dt;
  model.solver = scenario.solver;
  for (const Ligament& ligament : scenario.ligaments)
    model.ligaments.push_back({ligament.name, ligament.nodes, ligament.stiffness, {}});
  for (const Ligament& region : scenario.candidate_regions)
    model.candidate_regions.push_back({region.name, region.nodes, 0.0, {}});
  for (const Region& region : scenario.regions) {
    // Both Lame terms are proportional to E at a fixed Poisson's ratio.
    const double scale = region.young_modulus / scenario.material.young_modulus;
    for (int e : region.elements) {
      model.elements[static_cast<std::size_t>(e)].vlambda *= scale;
      model.elements[static_cast<std::size_t>(e)].vmu *= scale;
    }
    model.regions.push_back({region.name, region.elements, region.young_modulus});
  }
  model.control = {"control", scenario.control.nodes, scenario.control.stiffness, {}};
  model.control_start = scenario.control.start;
  // Effects the scenario declares part of the model (the observation-side ones act on the
  // data instead: the estimation subtracts a declared camera offset).
  apply_effects(scenario.effects, model);
  return model;
}

}  // namespace sigmafem
