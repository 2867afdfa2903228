// CG's preconditioner on Vulkan from a sparse Cholesky factor made on the host: z = M^-1 r
// for every sigma point, M = P^T L L^T P one factor that the sigma points share (of the
// representative's system: FactorisedPreconditioner, as OpenCL's CPU form has it).
// kernels/vulkan/factor_solve.comp does the two substitutions on L's 4 x 4 blocks
// (host/reference/factor_blocks.h), a lane per sigma point (on a device with subgroup
// shuffles: at S <= 4 several, split_lanes; from S = 5 in groups of 8 that read the blocks
// together, shares_blocks), in dispatches cut so that none
// turns its loops more often than llvmpipe allows (the shader's comment); VulkanEnsemble
// records them after CG's start and after each iteration's update.
#pragma once

#include <Eigen/SparseCore>

#include <cstddef>
#include <memory>
#include <utility>
#include <vector>

#include "device_layout.h"
#include "host/reference/factor_blocks.h"
#include "host/reference/factorised_preconditioner.h"
#include "host/reference/spring_correction.h"
#include "host/vulkan/vulkan_device.h"

namespace sigmafem {

class VulkanFactorSolve {
 public:
  // Lanes of a work-group of factor_solve: llvmpipe's 256-bit vector of floats.
  static constexpr int kLanes = 8;
  // Lanes a sigma point of `sigma_count` gets (factor_solve_split, kernels/vulkan/
  // factor_solve.comp): the most, a power of 2, that leave the group in kLanes and in one
  // subgroup, on a device with subgroup shuffles; else 1. On lavapipe (subgroups of 8): 8 at
  // S = 1, 4 at S = 2, 2 at S = 3 or 4, 1 from 5.
  static int split_lanes(const VulkanDeviceInfo& info, int sigma_count);
  int split() const { return split_; }
  // Whether a group of kLanes lanes, a sigma point each, reads each chunk of 8 blocks together
  // and passes them round by subgroup shuffles (factor_solve_shared): where there are shuffles
  // and subgroups of at least kLanes, and split_lanes gives 1.
  static bool shares_blocks(const VulkanDeviceInfo& info, int sigma_count);
  bool shared() const { return shared_; }

  // CG's buffers the solve reads and writes: r, z, d ([row S + s]), the active flags and r.z
  // (S each). Without z (none made) the solve stores only CG's d and r.z from z: record()
  // then needs a finish.
  struct CgBuffers {
    VulkanBuffer r, z, d, active, rz;
  };
  // For a factor of n rows and `sigma_count` sigma points, with a correction for each one's
  // springs at `spring_rows` rows (m; 0: none). `loop_turns`: the most a dispatch may turn
  // (DeviceOptions). The factor's buffers are made at the first upload of its pattern (their
  // size is its blocks').
  VulkanFactorSolve(VulkanDevice& device, int rows, int spring_rows, int sigma_count, const CgBuffers& cg,
                    long long loop_turns);

  // Sends a fresh factorisation (factor.ready(); after the first only the values go while
  // L's pattern stays, else the blocks' buffers are made anew), uncorrected until
  // upload_springs().
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
  bool ready() const { return layout_ != nullptr; }

  // Records z = M^-1 r for the sigma points still iterating, and after it `finish`
  // (SF_FACTOR_FINISH_*, device_layout.h: CG's r.z and d at the start or in an iteration):
  // the dispatches, each followed by a barrier. Needs ready().
  void record(VkCommandBuffer cmd, std::uint32_t finish = SF_FACTOR_FINISH_NONE) const;
  // Dispatches a solve takes with the pattern on the device.
  int dispatches() const { return static_cast<int>(ranges_.size()); }
  // Bytes of device memory the factor's buffers hold (they grow at an upload of a new pattern).
  std::size_t bytes() const { return bytes_; }

 private:
  // A pattern on the device: its blocks and their buffers, the pipeline (specialised to its
  // panels) and the descriptor set.
  // A new pattern's buffers are new ones (the last pattern's stay with the device: L's
  // pattern changes only from the stand-in to the first factor, or if A's does).
  struct Layout {
    std::unique_ptr<FactorBlocks> blocks;
    VulkanBuffer forward_starts, forward_panel, backward_starts, backward_panel, slot_rows, triangles,
        forward_blocks, backward_blocks, work;
    VulkanKernel kernel;
    VkDescriptorSet set = VK_NULL_HANDLE;
  };
  // L's values to the device: into the layout of its pattern, made if L's is another.
  void send(const Eigen::SparseMatrix<double>& L, const int* order);
  // A layout for L's pattern: its blocks, buffers, pipeline and descriptor set.
  void make_layout(const Eigen::SparseMatrix<double>& L, const int* order);
  void upload_values();
  // The correction's slots on the device: m and `reached`, then the reached rows' slots
  // (none: m = 0).
  void upload_spring_rows(int m, const std::vector<int>& reached);
  // ranges_ from the steps' loop turns.
  void plan_dispatches();
  VulkanBuffer make(std::size_t bytes);
  void upload_ints(const VulkanBuffer& buffer, const std::vector<int>& values);

  VulkanDevice& device_;
  int rows_ = 0, S_ = 0, spring_rows_ = 0;
  long long loop_turns_ = 0;
  std::size_t bytes_ = 0;
  CgBuffers cg_;
  VulkanBuffer spring_at_, spring_solves_, spring_coupling_;
  std::unique_ptr<Layout> layout_;
  // The correction's m and reached slots, and the dispatches: ranges [first, last) of the
  // steps (factor_solve.comp).
  std::pair<int, int> spring_steps_{0, 0};
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges_;
  std::uint32_t group_ = 1, groups_ = 1;
  int split_ = 1;                           // lanes a sigma point (split_lanes)
  bool shared_ = false;                     // shares_blocks
};

}  // namespace sigmafem
