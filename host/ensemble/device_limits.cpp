#include "host/ensemble/device_limits.h"

#include <algorithm>
#include <cstdint>
#include <stdexcept>

#include "host/common/input_error.h"
#include "host/ensemble/device_buffers.h"

namespace sigmafem {

double device_cg_tolerance(const Model& model, Precision precision) {
  return precision == Precision::single ? std::max(model.solver.cg_tolerance, kSingleCgTolerance)
                                        : model.solver.cg_tolerance;
}

void check_ensemble_arguments(const Model& model, const EstimatedParameters& estimated,
                              const ObservedPoints& observed, int S, const char* who) {
  const std::string name(who);
  if (S < 1) throw std::invalid_argument(name + ": need at least one sigma point");
  if (estimated.count() > kDeviceMaxParameters)
    throw std::invalid_argument(name + ": at most " + std::to_string(kDeviceMaxParameters) +
                                " estimated parameters");
  check_estimated_parameters(estimated, model, name);
  check_observed_points(observed, model.node_count(), who);
  // The kernels give every node of a ligament the same part of its stiffness (one number per
  // ligament and sigma point); the control's parts are per node and need no check.
  for (const SpringSet& ligament : model.ligaments)
    if (!ligament.shares.empty())
      throw InputError(name + ": ligament " + ligament.name +
                       " gives its nodes unequal parts of its stiffness (generate --truth-refine spreads each "
                       "spring over the refined mesh), which the device back ends do not hold: use --backend cpu");
}

int cg_partitions(int nodes, int forced) {
  if (forced > 0) return forced;
  return std::clamp(3 * nodes / kPartitionRows, 1, kMostPartitions);
}

CgGroups cg_groups(int nodes, int S, std::size_t real_size, int group_size, int forced_partitions,
                   int forced_lanes) {
  CgGroups groups;
  groups.partitions = cg_partitions(nodes, forced_partitions);
  if (forced_lanes > 0) {
    if (forced_lanes > group_size || group_size % forced_lanes != 0 || (forced_lanes & (forced_lanes - 1)) != 0)
      throw std::invalid_argument("cg_sigma_lanes: " + std::to_string(forced_lanes) +
                                  " is not a power of two that divides the work-group's " +
                                  std::to_string(group_size));
    groups.sigma_lanes = forced_lanes;
  } else if (groups.partitions > 1 && forced_partitions <= 0) {
    const int sector = std::max(1, static_cast<int>(kSectorBytes / real_size));
    int lanes = 1;
    while (lanes < S && lanes < sector && lanes < group_size) lanes *= 2;
    groups.sigma_lanes = lanes;
  }
  if (forced_partitions <= 0 && groups.partitions > 1)   // as many groups as with one lane
    groups.partitions = std::clamp(3 * nodes / kPartitionRows * groups.sigma_lanes, 1,
                                   kMostPartitions * groups.sigma_lanes);
  return groups;
}

EnsembleMemory ensemble_memory(int nodes, int elements, int S, std::size_t real_size,
                               std::size_t factor_nonzeros, FactorStorage storage, int factor_copies,
                               std::size_t frame_numbers) {
  // Per dof and sigma: x, v, dv, rhs, r, d, q, z unless Vulkan's blocks finish CG's step
  // without it, and without a factor the Jacobi diagonal; per element and sigma: the frame (9,
  // or Vulkan's 6), the element outputs (12) and without a factor diagonals (12).
  const bool factor = factor_nonzeros > 0;
  const std::size_t dof = 3 * static_cast<std::size_t>(nodes) * S;
  const std::size_t per_element = static_cast<std::size_t>(elements) * S;
  const std::size_t dof_vectors = !factor ? 9 : storage == FactorStorage::blocks ? 7 : 8;
  EnsembleMemory need;
  need.largest = 12 * per_element * real_size;
  need.total = (dof_vectors * dof + (frame_numbers + (factor ? 12 : 24)) * per_element) * real_size;
  if (!factor) return need;
  const std::size_t rows = 3 * static_cast<std::size_t>(nodes);
  if (storage == FactorStorage::columns) {
    // L's values (a copy a sigma point with own factors) and row indices, its column starts and
    // ordering, a work vector per sigma.
    const std::size_t values = factor_nonzeros * static_cast<std::size_t>(std::max(1, factor_copies)) * real_size;
    need.largest = std::max(need.largest, std::max(values, factor_nonzeros * sizeof(std::int32_t)));
    need.total += values + factor_nonzeros * sizeof(std::int32_t) +
                  (2 * rows + 1) * sizeof(std::int32_t) + dof * real_size;
  } else {
    // The blocks' entries each way, 1.5 a nonzero (1.38 measured on the 38k liver), a panel
    // index a block each way, and the work vector's copies (a sigma point's lanes, 8 at most).
    const std::size_t one_way = factor_nonzeros * 3 / 2 * real_size;
    need.largest = std::max(need.largest, one_way);
    need.total += 2 * one_way + 2 * (factor_nonzeros * 3 / 32) * sizeof(std::int32_t) +
                  rows * static_cast<std::size_t>(std::max(S, 8)) * real_size;
  }
  return need;
}

std::size_t multigrid_memory(const NestedMultigrid& multigrid, int S, std::size_t real_size) {
  const auto matrix = [&](const RowMajorMatrix& M) {
    return (static_cast<std::size_t>(M.rows()) + 1) * sizeof(std::int32_t) +
           static_cast<std::size_t>(M.nonZeros()) * (sizeof(std::int32_t) + real_size);
  };
  std::size_t bytes = 0;
  for (int l = 0; l < multigrid.level_count(); ++l) {
    const NestedMultigrid::Level& level = multigrid.level(l);
    const std::size_t vector = static_cast<std::size_t>(level.matrix.rows()) * S * real_size;
    bytes += matrix(multigrid.launch_matrix(l));
    if (!level.smoothing.empty())   // the diagonal, two coefficients a step, x and p twice
      bytes += (static_cast<std::size_t>(level.matrix.rows()) + 2 * level.smoothing.size()) * real_size + 4 * vector;
    if (l + 1 < multigrid.level_count()) bytes += matrix(level.prolongation) + matrix(level.restriction) + vector;
    if (l > 0) bytes += 2 * vector;   // b and the correction
  }
  return bytes + static_cast<std::size_t>(multigrid.level(0).matrix.rows()) * S * real_size;   // the shifts
}

std::size_t usable_device_memory(std::size_t memory, const DeviceOptions& options) {
  return options.device_memory > 0 ? std::min(memory, options.device_memory) : memory;
}

std::string memory_holder(const std::string& device, std::size_t memory, const DeviceOptions& options) {
  return usable_device_memory(memory, options) < memory ? device + " as held by --device-memory" : device;
}

std::string out_of_device_memory_message(const EnsembleMemory& need, int elements, int S,
                                         const std::string& device,
                                         std::size_t device_memory, std::size_t largest_buffer) {
  return "out of device memory: " + std::to_string(S) + " sigma points on " +
         std::to_string(elements) + " tetrahedra need about " + std::to_string(need.total >> 20) +
         " MiB (largest buffer " + std::to_string(need.largest >> 20) + " MiB); " + device +
         " has " + std::to_string(device_memory >> 20) + " MiB (largest buffer " +
         std::to_string(largest_buffer >> 20) +
         " MiB). Use fewer sigma points, a coarser mesh or another device";
}

std::string out_of_device_memory_message(const std::string& what, std::size_t more, std::size_t held,
                                         const std::string& device, std::size_t device_memory) {
  return "out of device memory: " + what + " need about " + std::to_string(more >> 20) + " MiB more than the " +
         std::to_string(held >> 20) + " MiB the ensemble holds; " + device + " has " +
         std::to_string(device_memory >> 20) +
         " MiB. Use fewer sigma points, a coarser mesh, --preconditioner jacobi or another device";
}

}  // namespace sigmafem
