#include "host/reference/factor_blocks.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace sigmafem {
namespace {

constexpr int kWidth = 4;   // a panel's columns: one vec4

// A panel's block as a 4 x 4 matrix from 16 values by columns.
Eigen::Matrix4d block_at(const std::vector<double>& values, std::size_t block) {
  return Eigen::Map<const Eigen::Matrix4d>(values.data() + 16 * block);
}

}  // namespace

FactorBlocks::FactorBlocks(const Eigen::SparseMatrix<double>& L, const int* order) {
  const int n = static_cast<int>(L.rows());
  if (L.cols() != n || !L.isCompressed())
    throw std::invalid_argument("FactorBlocks: L must be square and compressed");
  const int* starts = L.outerIndexPtr();
  const int* rows = L.innerIndexPtr();
  pattern_starts_.assign(starts, starts + n + 1);
  pattern_rows_.assign(rows, rows + L.nonZeros());
  for (int j = 0; j < n; ++j)
    if (starts[j] == starts[j + 1] || rows[starts[j]] != j)
      throw std::invalid_argument("FactorBlocks: L's column " + std::to_string(j) + " does not start at its diagonal");
  // Panels: column c joins the panel of c - 1 while it has room and the rows below c of
  // column c - 1 are those of column c (a supernode; the entry (c, c - 1) may be absent).
  auto below_matches = [&](int c) {
    int a = starts[c - 1] + 1;   // column c - 1 below its diagonal
    if (a < starts[c] && rows[a] == c) ++a;
    const int b = starts[c] + 1;
    if (starts[c] - a != starts[c + 1] - b) return false;
    return std::equal(rows + a, rows + starts[c], rows + b);
  };
  first_column_.push_back(0);
  for (int c = 1; c < n; ++c)
    if (c - first_column_.back() == kWidth || !below_matches(c)) first_column_.push_back(c);
  first_column_.push_back(n);
  const int P = panels();
  slot_of_row_.resize(static_cast<std::size_t>(n));
  slot_rows_.assign(static_cast<std::size_t>(kWidth * P), -1);
  std::vector<int> panel_of(static_cast<std::size_t>(n));
  for (int q = 0; q < P; ++q)
    for (int c = first_column_[q]; c < first_column_[q + 1]; ++c) {
      const int slot = kWidth * q + (c - first_column_[q]);
      panel_of[static_cast<std::size_t>(c)] = q;
      slot_of_row_[static_cast<std::size_t>(c)] = slot;
    }
  for (int i = 0; i < n; ++i) slot_rows_[static_cast<std::size_t>(slot(order[i]))] = i;
  // Each column panel's row panels below it, from its first column (the others' rows below
  // the panel are the same).
  std::vector<std::vector<int>> below(static_cast<std::size_t>(P));
  forward_starts_.assign(static_cast<std::size_t>(P) + 1, 0);
  for (int p = 0; p < P; ++p) {
    const int c0 = first_column_[p], end = first_column_[p + 1];
    for (int k = starts[c0]; k < starts[c0 + 1]; ++k) {
      if (rows[k] < end) continue;
      const int q = panel_of[static_cast<std::size_t>(rows[k])];
      if (below[p].empty() || below[p].back() != q) {
        below[p].push_back(q);
        ++forward_starts_[static_cast<std::size_t>(q) + 1];
      }
    }
  }
  for (int q = 0; q < P; ++q) forward_starts_[q + 1] += forward_starts_[q];
  // Block ids by rows (q, then p), the same blocks by columns (p, then q).
  const std::size_t B = static_cast<std::size_t>(forward_starts_.back());
  forward_panel_.resize(B);
  backward_panel_.reserve(B);
  backward_block_.reserve(B);
  backward_starts_.assign(1, 0);
  std::vector<int> next(forward_starts_.begin(), forward_starts_.end() - 1);
  std::vector<std::vector<int>> block_of(static_cast<std::size_t>(P));
  for (int p = 0; p < P; ++p) {
    for (const int q : below[p]) {
      const int id = next[static_cast<std::size_t>(q)]++;
      forward_panel_[static_cast<std::size_t>(id)] = p;
      block_of[p].push_back(id);
      backward_panel_.push_back(q);
      backward_block_.push_back(id);
    }
    backward_starts_.push_back(static_cast<int>(backward_panel_.size()));
  }
  // Where each of L's entries goes.
  entry_at_.resize(static_cast<std::size_t>(L.nonZeros()));
  for (int p = 0; p < P; ++p)
    for (int c = first_column_[p]; c < first_column_[p + 1]; ++c) {
      const int column = c - first_column_[p];
      std::size_t b = 0;   // walks block_of[p] as the rows rise
      for (int k = starts[c]; k < starts[c + 1]; ++k) {
        const int q = panel_of[static_cast<std::size_t>(rows[k])];
        const int row = slot(rows[k]) - kWidth * q;
        if (q == p) {
          entry_at_[static_cast<std::size_t>(k)] = -1 - (16LL * p + kWidth * column + row);
          continue;
        }
        while (b < block_of[p].size() && backward_panel_[static_cast<std::size_t>(backward_starts_[p]) + b] != q) ++b;
        if (b == block_of[p].size())
          throw std::logic_error("FactorBlocks: column " + std::to_string(c) + " leaves its panel's pattern");
        entry_at_[static_cast<std::size_t>(k)] = 16LL * block_of[p][b] + kWidth * column + row;
      }
    }
  assign_values(L);
}

bool FactorBlocks::same_pattern(const Eigen::SparseMatrix<double>& L) const {
  const std::size_t n = pattern_starts_.size() - 1;
  return L.isCompressed() && static_cast<std::size_t>(L.rows()) == n && static_cast<std::size_t>(L.cols()) == n &&
         std::equal(pattern_starts_.begin(), pattern_starts_.end(), L.outerIndexPtr()) &&
         std::equal(pattern_rows_.begin(), pattern_rows_.end(), L.innerIndexPtr());
}

void FactorBlocks::assign_values(const Eigen::SparseMatrix<double>& L) {
  if (!same_pattern(L)) throw std::invalid_argument("FactorBlocks: a factor of another pattern");
  const int P = panels();
  triangles_.assign(16 * static_cast<std::size_t>(P), 0.0);
  for (int p = 0; p < P; ++p)
    for (int c = first_column_[p + 1] - first_column_[p]; c < kWidth; ++c)
      triangles_[16 * static_cast<std::size_t>(p) + 5 * static_cast<std::size_t>(c)] = 1.0;
  forward_values_.assign(16 * blocks(), 0.0);
  const double* values = L.valuePtr();
  for (std::size_t k = 0; k < entry_at_.size(); ++k) {
    const long long at = entry_at_[k];
    if (at >= 0)
      forward_values_[static_cast<std::size_t>(at)] = values[k];
    else
      triangles_[static_cast<std::size_t>(-1 - at)] = values[k];
  }
  backward_values_.resize(forward_values_.size());
  for (std::size_t k = 0; k < backward_block_.size(); ++k)
    std::copy_n(forward_values_.begin() + 16 * static_cast<std::ptrdiff_t>(backward_block_[k]), 16,
                backward_values_.begin() + 16 * static_cast<std::ptrdiff_t>(k));
}

void FactorBlocks::solve(Eigen::VectorXd& y) const {
  const int P = panels();
  std::vector<Eigen::Vector4d> slots(static_cast<std::size_t>(P), Eigen::Vector4d::Zero());
  for (int q = 0; q < P; ++q) {   // L y = b, by block rows
    Eigen::Vector4d b = Eigen::Vector4d::Zero();
    for (int c = first_column_[q]; c < first_column_[q + 1]; ++c) b[c - first_column_[q]] = y[c];
    for (int k = forward_starts_[q]; k < forward_starts_[q + 1]; ++k)
      b -= block_at(forward_values_, static_cast<std::size_t>(k)) * slots[static_cast<std::size_t>(forward_panel_[k])];
    slots[static_cast<std::size_t>(q)] =
        block_at(triangles_, static_cast<std::size_t>(q)).triangularView<Eigen::Lower>().solve(b);
  }
  for (int p = P - 1; p >= 0; --p) {   // L^T w = y, by block columns
    Eigen::Vector4d a = slots[static_cast<std::size_t>(p)];
    for (int k = backward_starts_[p]; k < backward_starts_[p + 1]; ++k)
      a -= block_at(backward_values_, static_cast<std::size_t>(k)).transpose() *
           slots[static_cast<std::size_t>(backward_panel_[k])];
    slots[static_cast<std::size_t>(p)] =
        block_at(triangles_, static_cast<std::size_t>(p)).transpose().triangularView<Eigen::Upper>().solve(a);
  }
  for (int q = 0; q < P; ++q)
    for (int c = first_column_[q]; c < first_column_[q + 1]; ++c) y[c] = slots[static_cast<std::size_t>(q)][c - first_column_[q]];
}

}  // namespace sigmafem
