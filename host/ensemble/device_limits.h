// What a device ensemble may be asked and what it needs: its arguments checked, the CG
// tolerance it solves to, CG's work-groups per sigma point, and its device memory, with the
// message when the device has too little.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "host/common/device_options.h"
#include "host/mesh/observed_points.h"
#include "host/model/estimated_parameters.h"
#include "host/model/model.h"
#include "host/reference/nested_multigrid.h"

namespace sigmafem {

// Checks an ensemble's arguments: std::invalid_argument naming `who`.
void check_ensemble_arguments(const Model& model, const EstimatedParameters& estimated,
                              const ObservedPoints& observed, int sigma_count, const char* who);

// The CG tolerance floor of a float32 device ensemble: about ten float32 epsilons (float32
// cannot reach the scenario's 1e-10).
constexpr double kSingleCgTolerance = 1e-6;

// The CG tolerance a device ensemble solves to: the scenario's, raised to kSingleCgTolerance
// in single precision.
double device_cg_tolerance(const Model& model, Precision precision);

// The CG kernels' work-groups per sigma point on a GPU (kernels/opencl/conjugate_gradient.cl's
// SF_CG_PARTITIONS, specialization constant 1 of kernels/vulkan/conjugate_gradient.comp): one
// below 2 kPartitionRows rows (3 per node), then one per kPartitionRows rows, at most
// kMostPartitions. `forced` > 0 (DeviceOptions::cg_partitions) is taken as it is.
constexpr int kPartitionRows = 512;
constexpr int kMostPartitions = 64;
int cg_partitions(int nodes, int forced);

// OpenCL's GPU form and Vulkan on a GPU: how CG's work-groups lie over the rows [row S + s]
// (conjugate_gradient.cl's SF_CG_SIGMA_LANES; conjugate_gradient.comp's SF_LANE_ROWS, the
// group size over the lanes, in its partitions' shaders). A group's work-items are `sigma_lanes` sigma points side by side, so that
// a warp reads runs of consecutive entries; with one lane (a group per sigma point, as before)
// every work-item reads its own 32-byte sector for 4 bytes at S = 8 and up.
struct CgGroups {
  int partitions = 1;    // partitions of the rows (SF_CG_PARTITIONS)
  int sigma_lanes = 1;   // sigma points side by side in a group, a power of two
};
// Where cg_partitions gives one partition (a small mesh: CG's launches are latency, and one
// launch an iteration does it) one lane; else lanes up to a sector's worth of reals (8 floats,
// 4 doubles) or all S where fewer: then a row's S entries are one run with the next row's. The
// partitions grow with the lanes, so that the groups and the entries a group are as many as
// with one lane. `forced_partitions`, `forced_lanes` > 0 (DeviceOptions) are taken as they are,
// forced partitions with one lane unless lanes are forced too.
constexpr int kSectorBytes = 32;
CgGroups cg_groups(int nodes, int sigma_count, std::size_t real_size, int group_size,
                   int forced_partitions, int forced_lanes);

// How a device ensemble holds its shared factor: OpenCL's L by columns (its values and row
// indices), or Vulkan's dense 4 x 4 blocks by rows and by columns (VulkanFactorSolve: each way
// about 1.4 stored entries a nonzero; in all 12.2 bytes a nonzero in float32 on the 38k liver,
// bench/RESULTS.md, stop 59).
enum class FactorStorage { columns, blocks };

// Device memory of an ensemble, in bytes, for `real_size`-byte reals; with a shared factor of
// `factor_nonzeros` nonzeros (OpenCL's CPU form, Vulkan on a CPU device), its buffers too, and
// without Jacobi's diagonals (DeviceBufferSizes::jacobi_diagonals), and with Vulkan's blocks
// without z (DeviceBufferSizes::cg_z).
struct EnsembleMemory {
  std::size_t total = 0;     // about: all buffers
  std::size_t largest = 0;   // the largest single buffer (12 per element and sigma point, or L)
};
// OpenCL's own factors (`factor_copies` = S) hold S copies of L's values. `frame_numbers`:
// DeviceBufferSizes::frame_numbers (Vulkan keeps 6 of each frame's 9).
EnsembleMemory ensemble_memory(int nodes, int elements, int sigma_count, std::size_t real_size,
                               std::size_t factor_nonzeros = 0,
                               FactorStorage storage = FactorStorage::columns, int factor_copies = 1,
                               std::size_t frame_numbers = 9);

// The device buffers of a multigrid V-cycle (OpenClMultigrid, VulkanMultigrid: each level's
// matrix, prolongation and restriction by rows, its smoothing's diagonal and coefficients, its
// vectors for S sigma points, and the finest level's spring shifts), in bytes, once `multigrid`
// has its matrices (set_matrix): they are known only then.
std::size_t multigrid_memory(const NestedMultigrid& multigrid, int sigma_count, std::size_t real_size);

// The memory checks' share of a device's `memory`: DeviceOptions::device_memory where set and
// smaller; and the device's name for their messages, saying so then.
std::size_t usable_device_memory(std::size_t memory, const DeviceOptions& options);
std::string memory_holder(const std::string& device, std::size_t memory, const DeviceOptions& options);

// The "out of device memory" message: what the ensemble needs and what `device` has.
std::string out_of_device_memory_message(const EnsembleMemory& need, int elements,
                                         int sigma_count, const std::string& device,
                                         std::size_t device_memory, std::size_t largest_buffer);
// The message when `what`'s `more` bytes would take an ensemble of `held` bytes past
// `device`'s `device_memory`.
std::string out_of_device_memory_message(const std::string& what, std::size_t more, std::size_t held,
                                         const std::string& device, std::size_t device_memory);

}  // namespace sigmafem
