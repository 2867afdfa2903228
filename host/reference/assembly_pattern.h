// AssemblyPattern: the sparsity of the implicit-Euler matrix on a model's mesh (every
// element's 12x12 block, and the whole diagonal) and where each element's entries go in its
// value array. A factor's refresh (factorised_preconditioner.h) then fills the values in
// place instead of building and sorting 144 triplets per element, and, the pattern being the
// same at every refresh, the factor keeps its ordering (issue 18: on the 596-tetrahedron
// liver an assembly took 650 us with triplets, 270 us into the pattern, and a factorisation
// 1030 us with its ordering, 660 us without).
// Built once per mesh and shared, read-only, by the simulations of an ensemble.
#pragma once

#include <Eigen/SparseCore>
#include <cstddef>
#include <vector>

#include "host/model/model.h"

namespace sigmafem {

class AssemblyPattern {
 public:
  explicit AssemblyPattern(const Model& model);

  // A matrix with the pattern, every value zero (column-major, compressed).
  const Eigen::SparseMatrix<double>& zeros() const { return zeros_; }
  // The index in the value array of element e's entry (i, j) of its 12x12 block, i and j
  // being 3 * corner + axis.
  int element_slot(std::size_t e, int i, int j) const {
    return element_slots_[144 * e + 12 * static_cast<std::size_t>(j) + static_cast<std::size_t>(i)];
  }
  // The index of the diagonal entry of degree of freedom `dof`.
  int diagonal_slot(int dof) const { return diagonal_slots_[static_cast<std::size_t>(dof)]; }

 private:
  Eigen::SparseMatrix<double> zeros_;
  std::vector<int> element_slots_;    // 144 per element, column j's 12 rows together
  std::vector<int> diagonal_slots_;
};

}  // namespace sigmafem
