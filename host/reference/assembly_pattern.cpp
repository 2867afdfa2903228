#include "host/reference/assembly_pattern.h"

#include <algorithm>

namespace sigmafem {
namespace {

int dof_of(const ElementRest& element, int local) { return 3 * element.nodes[local / 3] + local % 3; }

// The index of entry (row, col) in a compressed column-major matrix that holds it.
int slot_of(const Eigen::SparseMatrix<double>& A, int row, int col) {
  const int* begin = A.innerIndexPtr() + A.outerIndexPtr()[col];
  const int* end = A.innerIndexPtr() + A.outerIndexPtr()[col + 1];
  return static_cast<int>(std::lower_bound(begin, end, row) - A.innerIndexPtr());
}

}  // namespace

AssemblyPattern::AssemblyPattern(const Model& model) {
  const int dofs = model.dof_count();
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(model.elements.size() * 144 + static_cast<std::size_t>(dofs));
  for (const ElementRest& element : model.elements)
    for (int j = 0; j < 12; ++j)
      for (int i = 0; i < 12; ++i) entries.emplace_back(dof_of(element, i), dof_of(element, j), 0.0);
  // The diagonal of a node that no element uses too: the mass and the springs go there.
  for (int d = 0; d < dofs; ++d) entries.emplace_back(d, d, 0.0);
  zeros_.resize(dofs, dofs);
  zeros_.setFromTriplets(entries.begin(), entries.end());
  zeros_.makeCompressed();

  element_slots_.resize(model.elements.size() * 144);
  for (std::size_t e = 0; e < model.elements.size(); ++e)
    for (int j = 0; j < 12; ++j)
      for (int i = 0; i < 12; ++i)
        element_slots_[144 * e + 12 * static_cast<std::size_t>(j) + static_cast<std::size_t>(i)] =
            slot_of(zeros_, dof_of(model.elements[e], i), dof_of(model.elements[e], j));
  diagonal_slots_.resize(static_cast<std::size_t>(dofs));
  for (int d = 0; d < dofs; ++d) diagonal_slots_[static_cast<std::size_t>(d)] = slot_of(zeros_, d, d);
}

}  // namespace sigmafem
