// AssemblyPattern (host/reference/assembly_pattern.h): every element entry and every diagonal
// entry, an unused node's included, has its slot in the pattern, and the tangent assembled
// into the slots is, bit for bit, the sum of the element blocks that triplets give in element
// order (the assembly it replaced). That the blocks are the element product's matrix is
// corotational_test.cpp's.
#include "host/reference/assembly_pattern.h"

#include <gtest/gtest.h>

#include <Eigen/SparseCore>
#include <vector>

#include "host/reference/corotational.h"
#include "host/reference/reference_simulation.h"
#include "tests/reference/structured_mesh.h"

namespace sigmafem {
namespace {

// The row and column of value index `slot` in a compressed column-major matrix.
std::pair<int, int> entry_of(const Eigen::SparseMatrix<double>& A, int slot) {
  int col = 0;
  while (A.outerIndexPtr()[col + 1] <= slot) ++col;
  return {A.innerIndexPtr()[slot], col};
}

TEST(AssemblyPattern, EveryElementEntryAndEveryDiagonalEntryHasItsSlot) {
  test::StructuredBox box = test::structured_box(Eigen::Vector3d(0.1, 0.06, 0.04), 3, 2, 2, 0.1);
  box.mesh.nodes.push_back(Eigen::Vector3d(1.0, 1.0, 1.0));   // a node no element uses
  const Model model = make_model(box.mesh, Material{3000.0, 0.45, 1000.0});
  const AssemblyPattern pattern(model);
  const Eigen::SparseMatrix<double>& A = pattern.zeros();
  ASSERT_TRUE(A.isCompressed());
  EXPECT_EQ(A.rows(), model.dof_count());
  for (int d = 0; d < model.dof_count(); ++d)
    EXPECT_EQ(entry_of(A, pattern.diagonal_slot(d)), std::make_pair(d, d)) << "dof " << d;
  for (std::size_t e = 0; e < model.elements.size(); ++e)
    for (int j = 0; j < 12; ++j)
      for (int i = 0; i < 12; ++i) {
        const int row = 3 * model.elements[e].nodes[i / 3] + i % 3;
        const int col = 3 * model.elements[e].nodes[j / 3] + j % 3;
        ASSERT_EQ(entry_of(A, pattern.element_slot(e, i, j)), std::make_pair(row, col))
            << "element " << e << " entry (" << i << ", " << j << ")";
      }
  for (Eigen::Index k = 0; k < A.nonZeros(); ++k) EXPECT_EQ(A.valuePtr()[k], 0.0);
}

TEST(AssemblyPattern, AssemblesTheSameBitsAsTripletsOfTheElementBlocks) {
  const test::HeldBox held = test::held_box();
  ReferenceSimulation simulation(held.model);
  for (int step = 1; step <= 20; ++step) simulation.step(test::held_box_so(held.model, step * held.model.dt));
  std::vector<Frame> frames;
  element_frames(held.model, simulation.positions(), frames);

  // The triplet assembly that the pattern replaced: the element blocks' entries summed by
  // setFromTriplets in element order.
  std::vector<Eigen::Triplet<double>> triplets;
  for (std::size_t e = 0; e < held.model.elements.size(); ++e) {
    const ElementRest& element = held.model.elements[e];
    double block[144];
    element_stiffness_block(frames[e].data(), element, block);
    for (int j = 0; j < 12; ++j)
      for (int i = 0; i < 12; ++i)
        triplets.emplace_back(3 * element.nodes[i / 3] + i % 3, 3 * element.nodes[j / 3] + j % 3,
                              block[12 * j + i]);
  }
  Eigen::SparseMatrix<double> expected(held.model.dof_count(), held.model.dof_count());
  expected.setFromTriplets(triplets.begin(), triplets.end());

  const Eigen::SparseMatrix<double> K =
      assemble_element_stiffness(held.model, frames, simulation.assembly_pattern());
  ASSERT_EQ(K.nonZeros(), expected.nonZeros()) << "every node of the box is in an element";
  for (int col = 0; col < K.cols(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(K, col); it; ++it)
      ASSERT_EQ(it.value(), expected.coeff(it.row(), col)) << "entry (" << it.row() << ", " << col << ")";
}

}  // namespace
}  // namespace sigmafem
