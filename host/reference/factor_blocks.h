// FactorBlocks: a sparse Cholesky factor L cut into dense 4 x 4 blocks, for substitutions that
// read four entries of L, and four of the vector, at a time (issue 18, item 3: Vulkan's
// factor_solve on lavapipe, kernels/vulkan/factor_solve.comp).
// L's columns are grouped into panels of up to 4 consecutive columns whose patterns below the
// panel are the same (nearly always a node's 3 columns or 4 columns of a wider supernode, so
// the blocks carry few zeros); row panels are the same groups of rows. Block (q, p), q > p,
// holds L's entries in row panel q and column panel p, by columns; the diagonal blocks are
// the panels' lower triangles. The vector is laid out by slots, 4 per panel (slot 4 q + c is
// the panel's row c, or padding). A substitution then turns once per block instead of once
// per entry of L: on the liver's factor 2 x 2334 blocks against 2 x 26 088 entries.
// Padding: a panel of fewer than 4 columns gets unit columns on the diagonal and zeros
// elsewhere, so that its padded slots solve to 0.
#pragma once

#include <Eigen/SparseCore>

#include <cstddef>
#include <vector>

namespace sigmafem {

class FactorBlocks {
 public:
  // Groups L (lower triangular by columns, each column's diagonal entry first, as Eigen's
  // SimplicialLLT makes it) into panels and blocks; `order` is the factor's ordering (order[i]
  // is original row i's position in L's rows). Then values() fills the blocks' entries.
  FactorBlocks(const Eigen::SparseMatrix<double>& L, const int* order);

  // Fills triangles() and the blocks from L's values (L of the pattern given to the
  // constructor: a later factorisation of the same analysis).
  void assign_values(const Eigen::SparseMatrix<double>& L);
  // Whether L has the pattern given to the constructor.
  bool same_pattern(const Eigen::SparseMatrix<double>& L) const;

  int panels() const { return static_cast<int>(first_column_.size()) - 1; }
  std::size_t blocks() const { return forward_panel_.size(); }
  // Slot of L's row i (4 q + c: panel q, its row c).
  int slot(int row) const { return slot_of_row_[static_cast<std::size_t>(row)]; }
  // The original row (P^T) of each slot, -1 for padding: 4 panels() entries.
  const std::vector<int>& slot_rows() const { return slot_rows_; }
  // By block row q: blocks forward_starts[q] .. forward_starts[q + 1], each block's column
  // panel p (< q); forward_values: 16 per block in that order, its 4 columns of 4 rows.
  const std::vector<int>& forward_starts() const { return forward_starts_; }
  const std::vector<int>& forward_panel() const { return forward_panel_; }
  const std::vector<double>& forward_values() const { return forward_values_; }
  // By block column p: the same blocks, each with its row panel q (> p), and their values in
  // this order.
  const std::vector<int>& backward_starts() const { return backward_starts_; }
  const std::vector<int>& backward_panel() const { return backward_panel_; }
  const std::vector<double>& backward_values() const { return backward_values_; }
  // 16 per panel: its diagonal block's 4 columns (lower triangular, unit where padded).
  const std::vector<double>& triangles() const { return triangles_; }

  // y := L^-T L^-1 y, y in L's order, on the blocks in double (the device's algorithm, for tests).
  void solve(Eigen::VectorXd& y) const;

 private:
  std::vector<int> pattern_starts_, pattern_rows_;   // L's pattern, as given
  std::vector<int> first_column_;            // panel q: L's columns first_column_[q] .. [q + 1]
  std::vector<int> slot_of_row_, slot_rows_;
  std::vector<int> forward_starts_, forward_panel_, backward_starts_, backward_panel_;
  std::vector<int> backward_block_;          // the k-th block by columns is block backward_block_[k] by rows
  // Where L's entry k (in its column storage) goes: in forward_values_ (>= 0) or, as -1 - at,
  // in triangles_.
  std::vector<long long> entry_at_;
  std::vector<double> forward_values_, backward_values_, triangles_;
};

}  // namespace sigmafem
