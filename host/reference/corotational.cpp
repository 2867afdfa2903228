#include "host/reference/corotational.h"

#include <Eigen/Dense>

#include "host/model/shared_element.h"

namespace sigmafem {
namespace {

void gather_corners(const ElementRest& element, const Eigen::VectorXd& v, double out[12]) {
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 3; ++k) out[3 * c + k] = v[3 * element.nodes[c] + k];
}

void scatter_add(const ElementRest& element, const double in[12], Eigen::VectorXd& v) {
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 3; ++k) v[3 * element.nodes[c] + k] += in[3 * c + k];
}

Eigen::Matrix3d frame_matrix(const double frame[9]) {
  Eigen::Matrix3d F;
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) F(r, k) = frame[3 * r + k];
  return F;
}

}  // namespace

void element_frames(const Model& model, const Eigen::VectorXd& x, std::vector<Frame>& frames) {
  frames.resize(model.elements.size());
  const double polar = model.material.rotation == ElementRotation::polar ? 1.0 : 0.0;
  double p[12];
  for (std::size_t e = 0; e < model.elements.size(); ++e) {
    gather_corners(model.elements[e], x, p);
    shared::sf_element_rotation(model.elements[e].grad.data(), p, polar, frames[e].data());
  }
}

void add_element_forces(const Model& model, const std::vector<Frame>& frames,
                        const Eigen::VectorXd& x, Eigen::VectorXd& f) {
  double p[12], fe[12];
  for (std::size_t e = 0; e < model.elements.size(); ++e) {
    const ElementRest& element = model.elements[e];
    gather_corners(element, x, p);
    shared::sf_element_force(frames[e].data(), element.grad.data(), element.vlambda, element.vmu, p,
                             fe);
    scatter_add(element, fe, f);
  }
}

void element_product(const Model& model, const std::vector<Frame>& frames,
                     const Eigen::VectorXd& d, Eigen::VectorXd& y) {
  y.setZero(d.size());
  double de[12], ye[12];
  for (std::size_t e = 0; e < model.elements.size(); ++e) {
    const ElementRest& element = model.elements[e];
    gather_corners(element, d, de);
    shared::sf_element_product(frames[e].data(), element.grad.data(), element.vlambda, element.vmu,
                               de, ye);
    scatter_add(element, ye, y);
  }
}

void element_stiffness_block(const double frame[9], const ElementRest& element, double block[144]) {
  // With F = frame and w_c = F^T grad_c (corner c's gradient on the world axes), element.h's
  // product of the unit vector of corner d, axis l gives at corner c, axis k
  //   vmu (grad_c . grad_d) delta_kl + vmu w_d,k w_c,l + vlambda w_c,k w_d,l,
  // since F^T F = I for both frames (QR and polar). Written out, about 700 flops against the
  // twelve products' 3200 (a factor's refresh assembles every element).
  const double* grad = element.grad.data();
  double w[4][3];
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 3; ++k)
      w[c][k] = frame[k] * grad[3 * c] + frame[3 + k] * grad[3 * c + 1] + frame[6 + k] * grad[3 * c + 2];
  for (int d = 0; d < 4; ++d)
    for (int c = 0; c < 4; ++c) {
      const double gg = grad[3 * c] * grad[3 * d] + grad[3 * c + 1] * grad[3 * d + 1] +
                        grad[3 * c + 2] * grad[3 * d + 2];
      for (int l = 0; l < 3; ++l)
        for (int k = 0; k < 3; ++k)
          block[12 * (3 * d + l) + 3 * c + k] = element.vmu * (w[d][k] * w[c][l] + (k == l ? gg : 0.0)) +
                                                element.vlambda * w[c][k] * w[d][l];
    }
}

void element_diagonal(const Model& model, const std::vector<Frame>& frames,
                      Eigen::VectorXd& diagonal) {
  diagonal.setZero(model.dof_count());
  double de[12];
  for (std::size_t e = 0; e < model.elements.size(); ++e) {
    const ElementRest& element = model.elements[e];
    shared::sf_element_diagonal(frames[e].data(), element.grad.data(), element.vlambda, element.vmu,
                                de);
    scatter_add(element, de, diagonal);
  }
}

Eigen::SparseMatrix<double> assemble_element_stiffness(const Model& model,
                                                       const std::vector<Frame>& frames,
                                                       const AssemblyPattern& pattern) {
  Eigen::SparseMatrix<double> K = pattern.zeros();
  double* values = K.valuePtr();
  double block[144];
  for (std::size_t e = 0; e < model.elements.size(); ++e) {
    element_stiffness_block(frames[e].data(), model.elements[e], block);
    // Each entry sums its elements' parts in element order.
    for (int j = 0; j < 12; ++j)
      for (int i = 0; i < 12; ++i) values[pattern.element_slot(e, i, j)] += block[12 * j + i];
  }
  return K;
}

Eigen::SparseMatrix<double> assemble_element_stiffness(const Model& model,
                                                       const std::vector<Frame>& frames) {
  return assemble_element_stiffness(model, frames, AssemblyPattern(model));
}

Eigen::Matrix3d element_rotation(const Model& model, const std::vector<Frame>& frames, int e) {
  const ElementRest& element = model.elements[e];
  double p0[12], rest_frame[9];
  for (int c = 0; c < 4; ++c)
    for (int k = 0; k < 3; ++k) p0[3 * c + k] = model.rest_positions[element.nodes[c]][k];
  shared::sf_element_frame(p0, rest_frame);
  // world <- current frame <- rest frame coordinates <- world
  return frame_matrix(frames[e].data()).transpose() * frame_matrix(rest_frame);
}

}  // namespace sigmafem
