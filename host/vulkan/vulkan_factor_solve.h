// CG's preconditioner on Vulkan from a sparse Cholesky factor made on the host: z = M^-1 r
// for every sigma point, M = P^T L L^T P one factor that the sigma points share (of the
// representative's system: FactorisedPreconditioner, as OpenCL's CPU form has it).
// kernels/vulkan/factor_solve.comp does the two substitutions, a lane per sigma point, in
// dispatches cut so that none turns its loops more often than llvmpipe allows (the shader's
// comment); VulkanEnsemble records them after CG's start and after each iteration's update.
#pragma once

#include <Eigen/SparseCore>

#include <cstddef>
#include <utility>
#include <vector>

#include "host/reference/factorised_preconditioner.h"
#include "host/reference/spring_correction.h"
#include "host/vulkan/vulkan_device.h"

namespace sigmafem {

class VulkanFactorSolve {
 public:
  // Sigma points a work-group of factor_solve takes: llvmpipe's 256-bit vector of floats.
  static constexpr int kLanes = 8;

  // Room for a factor of n rows and `nonzeros` entries (FactorisedPreconditioner::nonzeros()
  // after analyse()) for `sigma_count` sigma points, with a correction for each one's springs
  // at `spring_rows` rows (m; 0: none); r, z and the active flags are CG's buffers,
  // [row S + s]. `loop_turns`: the most a dispatch may turn (DeviceOptions).
  VulkanFactorSolve(VulkanDevice& device, int rows, std::size_t nonzeros, int spring_rows,
                    int sigma_count, const VulkanBuffer& r, const VulkanBuffer& z,
                    const VulkanBuffer& active, long long loop_turns);

  // Sends a fresh factorisation (factor.ready(); its pattern is the analysis's, so after the
  // first only the values go), uncorrected until upload_springs().
  void upload(const FactorisedPreconditioner& factor);
  // The correction of the factor just uploaded (springs.prepare()d with it; its m the
  // constructor's). False, and the factor left uncorrected, where one of the correction's sums
  // would turn more loops than one dispatch may.
  bool upload_springs(const SpringCorrection& springs);
  // Records each sigma point's coupling H ([(s m + j) m + k], S m^2 reals) for the correction,
  // into `cmd` (no host wait; the caller's barrier follows).
  void record_couplings(VkCommandBuffer cmd, const std::vector<double>& couplings) const;
  // A stand-in until a factorisation succeeds: L = sqrt|diag A|, no reordering, so that
  // z = r / |diag A|, Jacobi's preconditioner.
  void upload_diagonal(const Eigen::SparseMatrix<double>& A);
  // Whether a factor (or the stand-in) is on the device.
  bool ready() const { return pattern_ != Pattern::none; }

  // Records z = M^-1 r for the sigma points still iterating: the dispatches, each followed
  // by a barrier. Needs ready().
  void record(VkCommandBuffer cmd) const;
  // Dispatches a solve takes with the pattern on the device.
  int dispatches() const { return static_cast<int>(ranges_.size()); }
  // Bytes of device memory the factor's buffers hold.
  std::size_t bytes() const { return bytes_; }

 private:
  // L by rows and by columns, each row's original row (P^T), in the pattern given; the
  // dispatch ranges cut from it.
  void upload_pattern(const std::vector<int>& row_starts, const std::vector<int>& row_columns,
                      const std::vector<int>& column_starts, const std::vector<int>& column_rows,
                      const std::vector<int>& original_row);
  void upload_values(const std::vector<double>& row_values, const std::vector<double>& column_values);
  // The correction's rows on the device: m and `reached`, then those rows (none: m = 0).
  void upload_spring_rows(int m, const std::vector<int>& reached);
  // ranges_ from the steps' loop turns.
  void plan_dispatches();
  VulkanBuffer make(std::size_t bytes);
  void upload_ints(const VulkanBuffer& buffer, const std::vector<int>& values);

  VulkanDevice& device_;
  int rows_ = 0, S_ = 0, spring_rows_ = 0;
  std::size_t nonzeros_ = 0;
  long long loop_turns_ = 0;
  std::size_t bytes_ = 0;
  enum class Pattern { none, diagonal, factor };
  Pattern pattern_ = Pattern::none;
  // The factor's pattern in L's column storage -> its place in the row storage.
  std::vector<std::size_t> row_position_;
  // The loop turns of each forward row's step and each backward column's (by column), the
  // correction's m and reached rows, and the dispatches: ranges [first, last) of the steps
  // (factor_solve.comp).
  std::vector<long long> forward_turns_, backward_turns_;
  std::pair<int, int> spring_steps_{0, 0};
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges_;
  VulkanBuffer row_starts_, row_columns_, row_values_, column_starts_, column_rows_,
      column_values_, original_row_, work_, spring_at_, spring_solves_, spring_coupling_;
  VulkanKernel kernel_;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  std::uint32_t groups_ = 1;
};

}  // namespace sigmafem
