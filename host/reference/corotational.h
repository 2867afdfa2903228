// The co-rotational elastic forces and tangent of a whole mesh, in double precision: the
// CPU reference of the device kernels of the same names (element_frames, element_force,
// element_product, element_diagonal). Each loops over the elements and calls the shared
// element math of kernels/shared/element.h.
//
// Vectors of the whole mesh are flat, node-major: v[3 * node + axis].
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <array>
#include <vector>

#include "host/model/model.h"
#include "host/reference/assembly_pattern.h"

namespace sigmafem {

using Frame = std::array<double, 9>;   // element frame, rows = axes (element.h)

// The frame of every element at positions x (the "rotations" step).
void element_frames(const Model& model, const Eigen::VectorXd& x, std::vector<Frame>& frames);

// f += the elastic forces at positions x, with the frames of x.
void add_element_forces(const Model& model, const std::vector<Frame>& frames,
                        const Eigen::VectorXd& x, Eigen::VectorXd& f);

// y = K d, K = sum over elements of R K_e R^T (the elastic tangent stiffness).
void element_product(const Model& model, const std::vector<Frame>& frames,
                     const Eigen::VectorXd& d, Eigen::VectorXd& y);

// The diagonal of the elastic tangent stiffness.
void element_diagonal(const Model& model, const std::vector<Frame>& frames,
                      Eigen::VectorXd& diagonal);

// R K_e R^T of one element at its frame: entry (i, j), i and j being 3 * corner + axis, at
// block[12 j + i]; element_product's matrix (to rounding), written out for assembly.
void element_stiffness_block(const double frame[9], const ElementRest& element, double block[144]);

// The elastic tangent stiffness as a sparse matrix with the pattern's sparsity (the
// factors, the direct solve); without one, a pattern made for the call (the tests).
Eigen::SparseMatrix<double> assemble_element_stiffness(const Model& model,
                                                       const std::vector<Frame>& frames,
                                                       const AssemblyPattern& pattern);
Eigen::SparseMatrix<double> assemble_element_stiffness(const Model& model,
                                                       const std::vector<Frame>& frames);

// The rotation R of element e (rest frame to current frame, world coordinates): R maps the
// element's rest edges onto the directions of its current edges' frame.
Eigen::Matrix3d element_rotation(const Model& model, const std::vector<Frame>& frames, int e);

}  // namespace sigmafem
