// CG's preconditioner in Vulkan's GPU form where the mesh is a refinement: NestedMultigrid's
// V-cycle (host/reference/nested_multigrid.h) for all S sigma points at once, z = M^-1 r with r
// and z CG's buffers ([row S + s]); OpenCL's OpenClMultigrid does the same. The levels' CSR
// matrices go down at every NestedMultigrid::set_matrix (their patterns, and so the buffers and
// descriptor sets, stay those of the first); the V-cycle is a fixed list of dispatches of
// kernels/vulkan/multigrid.comp, each followed by a barrier, recorded into the step's command
// buffer after CG's start and each iteration's update.
#pragma once

#include <cstddef>
#include <vector>

#include "host/reference/nested_multigrid.h"
#include "host/vulkan/vulkan_device.h"
#include "host/vulkan/vulkan_push_constants.h"

namespace sigmafem {

class VulkanMultigrid {
 public:
  VulkanMultigrid(VulkanDevice& device, int sigma_count, const VulkanBuffer& r, const VulkanBuffer& z);

  // The hierarchy's matrices, diagonals and smoothing steps (`multigrid` ready). Throws
  // DeviceError when a level's pattern differs from the first upload's.
  void upload(const NestedMultigrid& multigrid);
  bool ready() const { return !dispatches_.empty(); }
  // Records each sigma point's shift at the finest level (rows x S reals, [row S + s]) into
  // `cmd` (no host wait; the caller's barrier follows). Needs ready().
  void record_shift(VkCommandBuffer cmd, const std::vector<double>& shift) const;
  // Records z = M^-1 r: the dispatches, each followed by a barrier. Needs ready().
  void record(VkCommandBuffer cmd) const;
  int dispatches() const { return static_cast<int>(dispatches_.size()); }
  // Bytes of device memory it holds.
  std::size_t bytes() const { return bytes_; }

 private:
  struct Matrix {
    VulkanBuffer row_start, columns, values;
    std::uint32_t rows = 0;
    std::size_t nonzeros = 0;
  };
  struct Level {
    Matrix matrix, prolongation, restriction;   // matrix: NestedMultigrid::launch_matrix
    VulkanBuffer diagonal, steps;
    // [row S + s]: the right-hand side and the result (coarser levels; the finest has CG's r
    // and z), the smoothing's iterates and steps (a step reads one, writes the other), the
    // residual.
    VulkanBuffer b, correction, x[2], p[2], r;
  };
  struct Dispatch {
    const VulkanKernel* kernel;
    VkDescriptorSet set;
    VulkanPushConstants push;
    std::uint32_t groups;
  };
  VulkanBuffer make(std::size_t bytes);
  Matrix make_matrix(const RowMajorMatrix& M);
  void upload_matrix(const Matrix& to, const RowMajorMatrix& M);
  // The buffers of every level, at the first upload.
  void make_levels(const NestedMultigrid& multigrid);
  // The dispatches of the V-cycle's launches (NestedMultigrid::launches), with their sets.
  void plan(const std::vector<MultigridLaunch>& launches);
  void add(const VulkanKernel& kernel, const Matrix& matrix, std::vector<VulkanBuffer> bound,
           std::uint32_t step, std::uint32_t flags);

  VulkanDevice& device_;
  int S_;
  VulkanBuffer r_, z_, shift_, none_;   // none_: bound where a shader reads no buffer
  std::vector<Level> levels_;
  std::vector<Dispatch> dispatches_;
  std::size_t bytes_ = 0;
  VulkanKernel k_smooth_, k_residual_, k_product_;
};

}  // namespace sigmafem
