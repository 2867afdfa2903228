// DeviceBuffer: every buffer of a device ensemble, one table for every back end (OpenCL,
// Vulkan): its name, element type, size and first contents (device_buffer_specs), and which
// buffers each kernel takes in the order of its buffer arguments (OpenCL, after the scalars)
// and of its bindings (Vulkan: binding i is entry i). Layout, sigma index innermost: value k of
// node n for sigma point s at [(3n + k) S + s] (kernels/opencl/ensemble_layout.h).
// Also what the host writes into them: the ligament stiffnesses from the filter's theta and the
// re-centring's inputs.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "filter/ensemble.h"
#include "host/mesh/observed_points.h"
#include "host/model/model.h"
#include "host/model/estimated_parameters.h"
#include "step_constants.h"

namespace sigmafem {

// Estimated parameters a device ensemble takes at most (kernels/shared/step_constants.h).
constexpr int kDeviceMaxParameters = SF_MAX_PARAMETERS;

enum class DeviceBuffer : int {
  // Shared by all sigma points: the mesh and its element rest state (grad[12], vlambda, vmu,
  // 0, 0 per element), the node incidence (CSR: corners 4 e + c of node n in element order,
  // so the node kernels gather without atomics, the same sums every run), the ligaments on
  // each node (CSR), the control springs and mass per node, the rest positions, the observed
  // points' corners and weights, the step constants (kernels/shared/step_constants.h).
  element_nodes, element_rest, incidence_offsets, incidence, ligament_offsets,
  ligament_of_node, control_k, mass, rest_positions, observed_nodes, observed_weights,
  constants,
  // Per sigma point: the ligaments' stiffness per node ([l S + s], N/m), the state, CG's
  // vectors, the element frames, the element outputs (12 per element; the CPU form of
  // OpenCL's element_product keeps a copy of K d per chunk there instead) and diagonals,
  // the gathered observations.
  ligament_k, x, v, dv, rhs, inverse_diagonal, r, z, d, q, frames, element_out,
  element_diagonal, observations,
  // CG's per-sigma scalars and flags; all_active: S ones, for products outside CG.
  bb, rr, rz, active, converged, iterations, all_active,
  // CG's partitions: partial sums and each (sigma point, partition) group's own scalars.
  partial, own_active, own_iterations, own_rz,
  // The re-centring's inputs (pack_recentering).
  recenter_scalars, directions, weights,
  // A sparse Cholesky factor of one sigma point's system as CG's preconditioner (OpenCL's CPU
  // form with --preconditioner factorised; one element each without): L by columns (each
  // column's start, its rows and values, the diagonal first), the ordering, and a work vector
  // per sigma point (FactorisedPreconditioner).
  factor_columns, factor_rows, factor_values, factor_order, factor_work,
  // The shared factor's correction for each sigma point's own springs (SpringCorrection): the
  // count of the rows of L that V = L^-1 P E reaches, then those rows; V's values there by
  // rows ([u m + j]); each sigma point's m x m coupling H ([(s m + j) m + k]).
  spring_at, spring_solves, spring_coupling,
  count
};
constexpr int kDeviceBufferCount = static_cast<int>(DeviceBuffer::count);

// A buffer's element type, size and contents before the first step.
struct DeviceBufferSpec {
  DeviceBuffer id = DeviceBuffer::count;
  const char* what = "";          // for "allocating <what>" errors
  bool integer = false;           // int32 (indices, flags) or a device real
  std::size_t count = 0;          // elements (at least 1)
  std::vector<double> reals;      // first contents; empty: none (written before it is read)
  std::vector<int> integers;      // first contents of an integer buffer (always given)
};

// What differs between the back ends' buffers.
struct DeviceBufferSizes {
  std::size_t element_out = 0;    // at least 12 per element and sigma point
  int cg_partitions = 1;          // CG work-groups per sigma point
  std::size_t factor_nonzeros = 0;   // of CG's factor, if it has one (0: Jacobi)
  int factor_copies = 1;             // of L's values: 1 shared, S when each sigma point has its own
  int spring_rows = 0;               // m of the factor's SpringCorrection (0: none)
  // Jacobi's diagonals (element_diagonal, inverse_diagonal: 12 E S + 3 N S reals); false with a
  // factor, whose kernels leave them out (*_factor, SF_FACTOR): one element each.
  bool jacobi_diagonals = true;
  // CG's z (3 N S reals); false with Vulkan's factor, whose solve finishes CG's step (r.z and
  // the direction) without storing z, and whose CG shaders (SF_FACTOR) leave it out: one element.
  bool cg_z = true;
  // Numbers of each element frame (per element and sigma point): 9, or SF_FRAME_TWO_ROWS where
  // the kernels keep its first two rows only (Vulkan; device_layout.h).
  std::size_t frame_numbers = 9;
};

// Every buffer of an ensemble of `model` with S sigma points, in DeviceBuffer order. The
// elements of estimated_regions[k] (indices into model.regions) get region slot 1 + k.
std::vector<DeviceBufferSpec> device_buffer_specs(const Model& model, const ObservedPoints& observed,
                                                  int S, std::size_t step_constant_count,
                                                  const DeviceBufferSizes& sizes,
                                                  const std::vector<int>& estimated_regions = {});

// The kernels that both back ends have, and Vulkan's two CG binding sets (the start's shaders,
// the iteration's), and the buffers each takes, in argument/binding order.
enum class DeviceKernel { element_rhs, node_rhs, element_product, node_product, state_update,
                          observation_gather, recenter, vulkan_cg_start, vulkan_cg_iteration };
const std::vector<DeviceBuffer>& kernel_buffers(DeviceKernel kernel);
// `buffers` with `from` replaced by `to` (a kernel run on other inputs: element_product on dv).
std::vector<DeviceBuffer> with_buffer(std::vector<DeviceBuffer> buffers, DeviceBuffer from,
                                      DeviceBuffer to);
// The index of `buffer` in kernel's list (its argument after the scalars, its binding).
int buffer_slot(DeviceKernel kernel, DeviceBuffer buffer);

// Writes exp(theta(j, s)) / (nodes of ligament estimated.ligaments[j]) into ligament_k, and
// returns the estimated regions' scales exp(theta(region row k, s)) / (model modulus), one
// row per estimated region (StepConstants::set_region_scales).
Eigen::MatrixXd parameters_from_theta(const Model& model, const EstimatedParameters& estimated,
                                      const Eigen::MatrixXd& theta, int sigma_count,
                                      std::vector<double>& ligament_k);

// The re-centring inputs, packed as the recenter kernels read them: scalars[1 + max p]
// (alpha, the correction), directions and weights W = C I, each [j S + s]. p is the filter's
// parameter count, which may exceed the ensemble's own (EffectEnsemble adds effect
// parameters): re-sampling the states does not depend on what the parameters are. Throws
// std::invalid_argument when the sizes disagree or p exceeds kDeviceMaxParameters.
struct RecenteringInputs {
  std::uint32_t p = 0;
  std::vector<double> scalars, directions, weights;
};
RecenteringInputs pack_recentering(const Recentering& r, int sigma_count, const char* who);

}  // namespace sigmafem
