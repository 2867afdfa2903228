#include "host/vulkan/vulkan_factor_solve.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "device_layout.h"
#include "host/ensemble/device_readout.h"
#include "host/vulkan/vulkan_push_constants.h"

namespace sigmafem {

VulkanFactorSolve::VulkanFactorSolve(VulkanDevice& device, int rows, std::size_t nonzeros,
                                     int spring_rows, int sigma_count, const VulkanBuffer& r,
                                     const VulkanBuffer& z, const VulkanBuffer& active,
                                     long long loop_turns)
    : device_(device), rows_(rows), S_(sigma_count), spring_rows_(spring_rows),
      nonzeros_(std::max<std::size_t>(nonzeros, static_cast<std::size_t>(rows))),
      loop_turns_(loop_turns) {
  const std::size_t n = static_cast<std::size_t>(rows), real = device_.real_size();
  row_starts_ = make(4 * (n + 1));
  row_columns_ = make(4 * nonzeros_);
  row_values_ = make(real * nonzeros_);
  column_starts_ = make(4 * (n + 1));
  column_rows_ = make(4 * nonzeros_);
  column_values_ = make(real * nonzeros_);
  original_row_ = make(4 * n);
  // y's n rows, then V^T y and H V^T y (factor_solve.comp).
  const std::size_t m = static_cast<std::size_t>(spring_rows_);
  work_ = make(real * (n + 2 * m) * static_cast<std::size_t>(S_));
  spring_at_ = make(4 * (2 + n));
  spring_solves_ = make(real * n * m);
  spring_coupling_ = make(real * m * m * static_cast<std::size_t>(S_));
  upload_spring_rows(0, {});
  const std::uint32_t group = static_cast<std::uint32_t>(std::min(S_, kLanes));
  groups_ = (static_cast<std::uint32_t>(S_) + group - 1) / group;
  kernel_ = device_.kernel("factor_solve", SF_FACTOR_SOLVE_SPRING_COUPLING + 1, group,
                           static_cast<std::uint32_t>(rows));
  set_ = device_.bind(kernel_, {row_starts_, row_columns_, row_values_, column_starts_, column_rows_,
                                column_values_, original_row_, r, z, active, work_, spring_at_,
                                spring_solves_, spring_coupling_});
}

VulkanBuffer VulkanFactorSolve::make(std::size_t bytes) {
  bytes_ += bytes;
  return device_.buffer(bytes, "the factor");
}

void VulkanFactorSolve::upload_ints(const VulkanBuffer& buffer, const std::vector<int>& values) {
  device_.upload(buffer, values.data(), values.size() * sizeof(int));
}

void VulkanFactorSolve::upload(const FactorisedPreconditioner& factor) {
  const Eigen::SparseMatrix<double>& L = factor.lower();
  const std::size_t n = static_cast<std::size_t>(rows_), entries = static_cast<std::size_t>(L.nonZeros());
  if (L.rows() != rows_ || entries > nonzeros_)
    throw DeviceError("the factor has " + std::to_string(entries) + " entries in " +
                      std::to_string(L.rows()) + " rows; the Vulkan buffers hold " +
                      std::to_string(nonzeros_) + " in " + std::to_string(rows_));
  const int* starts = L.outerIndexPtr();
  const int* rows = L.innerIndexPtr();
  if (pattern_ != Pattern::factor) {
    // L by rows: each column's entries appended to their rows in column order, so that a
    // row's diagonal (its largest column) comes last.
    std::vector<int> row_starts(n + 1, 0), row_columns(entries), original_row(n);
    for (std::size_t k = 0; k < entries; ++k) ++row_starts[static_cast<std::size_t>(rows[k]) + 1];
    for (std::size_t i = 0; i < n; ++i) row_starts[i + 1] += row_starts[i];
    std::vector<int> next(row_starts.begin(), row_starts.end() - 1);
    row_position_.resize(entries);
    for (std::size_t j = 0; j < n; ++j)
      for (int k = starts[j]; k < starts[j + 1]; ++k) {
        const std::size_t at = static_cast<std::size_t>(next[static_cast<std::size_t>(rows[k])]++);
        row_columns[at] = static_cast<int>(j);
        row_position_[static_cast<std::size_t>(k)] = at;
      }
    for (std::size_t i = 0; i < n; ++i) original_row[static_cast<std::size_t>(factor.order()[i])] = static_cast<int>(i);
    upload_pattern(row_starts, row_columns, std::vector<int>(starts, starts + n + 1),
                   std::vector<int>(rows, rows + entries), original_row);
    pattern_ = Pattern::factor;
  }
  std::vector<double> row_values(entries), column_values(L.valuePtr(), L.valuePtr() + entries);
  for (std::size_t k = 0; k < entries; ++k) row_values[row_position_[k]] = column_values[k];
  upload_values(row_values, column_values);
  upload_spring_rows(0, {});   // the last correction was the last factor's
}

bool VulkanFactorSolve::upload_springs(const SpringCorrection& springs) {
  if (springs.size() != spring_rows_ || !springs.prepared())
    throw DeviceError("the factor's spring correction has " + std::to_string(springs.size()) +
                      " rows (prepared: " + (springs.prepared() ? "yes" : "no") +
                      "); the Vulkan buffers hold " + std::to_string(spring_rows_));
  // A step of the correction sums over the reached rows or over m (factor_solve.comp).
  const long long longest = std::max<long long>(springs.size(), static_cast<long long>(springs.reached().size()));
  if (longest + 2 > loop_turns_) return false;
  const Eigen::MatrixXd& V = springs.reached_values();
  std::vector<double> values(static_cast<std::size_t>(V.size()));   // by rows
  for (Eigen::Index u = 0; u < V.rows(); ++u)
    for (Eigen::Index j = 0; j < V.cols(); ++j) values[static_cast<std::size_t>(u * V.cols() + j)] = V(u, j);
  const std::vector<unsigned char> bytes = to_device_reals(values, device_.precision());
  if (!bytes.empty()) device_.upload(spring_solves_, bytes.data(), bytes.size());
  upload_spring_rows(springs.size(), springs.reached());
  return true;
}

void VulkanFactorSolve::record_couplings(VkCommandBuffer cmd, const std::vector<double>& couplings) const {
  const std::size_t m = static_cast<std::size_t>(spring_rows_);
  if (couplings.size() != m * m * static_cast<std::size_t>(S_))
    throw DeviceError("the springs' couplings: " + std::to_string(couplings.size()) + " reals for " +
                      std::to_string(m * m * static_cast<std::size_t>(S_)));
  const std::vector<unsigned char> bytes = to_device_reals(couplings, device_.precision());
  device_.update(cmd, spring_coupling_, bytes.data(), bytes.size());
}

void VulkanFactorSolve::upload_spring_rows(int m, const std::vector<int>& reached) {
  std::vector<int> at = {m, static_cast<int>(reached.size())};
  at.insert(at.end(), reached.begin(), reached.end());
  upload_ints(spring_at_, at);
  spring_steps_ = {m, static_cast<int>(reached.size())};
  plan_dispatches();
}

void VulkanFactorSolve::upload_diagonal(const Eigen::SparseMatrix<double>& A) {
  const std::size_t n = static_cast<std::size_t>(rows_);
  std::vector<int> starts(n + 1), identity(n);
  for (std::size_t i = 0; i <= n; ++i) starts[i] = static_cast<int>(i);
  for (std::size_t i = 0; i < n; ++i) identity[i] = static_cast<int>(i);
  const std::vector<double> values = diagonal_stand_in(A);
  upload_pattern(starts, identity, starts, identity, identity);
  upload_values(values, values);
  upload_spring_rows(0, {});
  pattern_ = Pattern::diagonal;
}

void VulkanFactorSolve::upload_pattern(const std::vector<int>& row_starts, const std::vector<int>& row_columns,
                                       const std::vector<int>& column_starts, const std::vector<int>& column_rows,
                                       const std::vector<int>& original_row) {
  upload_ints(row_starts_, row_starts);
  upload_ints(row_columns_, row_columns);
  upload_ints(column_starts_, column_starts);
  upload_ints(column_rows_, column_rows);
  upload_ints(original_row_, original_row);
  // A substitution's step turns once and once per entry of its row or column besides the
  // diagonal, and its loop once more on leaving (counted with the step, to be safe).
  const std::size_t n = static_cast<std::size_t>(rows_);
  forward_turns_.resize(n);
  backward_turns_.resize(n);
  for (std::size_t j = 0; j < n; ++j) {
    forward_turns_[j] = row_starts[j + 1] - row_starts[j] + 1;
    backward_turns_[j] = column_starts[j + 1] - column_starts[j] + 1;
  }
  plan_dispatches();
}

void VulkanFactorSolve::plan_dispatches() {
  // The steps of factor_solve.comp (the forward rows, the correction's 2m + u, the backward
  // columns from the last) cut into ranges of at most loop_turns_ turns.
  ranges_.clear();
  if (forward_turns_.empty()) return;
  const auto [m, reached] = spring_steps_;
  std::vector<long long> turns(forward_turns_);
  turns.insert(turns.end(), static_cast<std::size_t>(m), reached + 2);   // (V^T y)_j
  turns.insert(turns.end(), static_cast<std::size_t>(m), m + 2);         // (H V^T y)_j
  turns.insert(turns.end(), static_cast<std::size_t>(reached), m + 2);   // y -= V H V^T y, a row
  turns.insert(turns.end(), backward_turns_.rbegin(), backward_turns_.rend());
  long long sum = 0;
  std::uint32_t first = 0;
  for (std::size_t step = 0; step < turns.size(); ++step) {
    if (turns[step] > loop_turns_)
      throw DeviceError("the factor's step " + std::to_string(step) + " turns " + std::to_string(turns[step]) +
                        " times, more than a Vulkan dispatch may turn (" + std::to_string(loop_turns_) +
                        " loop turns)");
    if (sum + turns[step] > loop_turns_) {
      ranges_.emplace_back(first, static_cast<std::uint32_t>(step));
      first = static_cast<std::uint32_t>(step);
      sum = 0;
    }
    sum += turns[step];
  }
  ranges_.emplace_back(first, static_cast<std::uint32_t>(turns.size()));
}

void VulkanFactorSolve::upload_values(const std::vector<double>& row_values,
                                      const std::vector<double>& column_values) {
  const std::vector<unsigned char> rows = to_device_reals(row_values, device_.precision());
  const std::vector<unsigned char> columns = to_device_reals(column_values, device_.precision());
  device_.upload(row_values_, rows.data(), rows.size());
  device_.upload(column_values_, columns.data(), columns.size());
}

void VulkanFactorSolve::record(VkCommandBuffer cmd) const {
  VulkanPushConstants push;   // S, the first step, one past the last (factor_solve.comp)
  push.S = static_cast<std::uint32_t>(S_);
  for (const auto& [first, last] : ranges_) {
    push.count = first;
    push.p = last;
    device_.dispatch(cmd, kernel_, set_, &push, groups_);
    device_.barrier(cmd);
  }
}

}  // namespace sigmafem
