// EnsembleTables: what every device back end (OpenCL, Vulkan) uploads and packs on the host,
// built once here from a Model so that the back ends share one definition of the layout
// (kernels/opencl/ensemble_layout.h, kernels/vulkan/ensemble_layout.h):
//   shared data    one copy for all sigma points (mesh, rest state, springs, mass)
//   per-sigma data sigma index innermost: value k of node n for sigma s at [(3n + k) S + s]
// Also the per-step constants, the per-sigma ligament stiffnesses from the filter's theta,
// the re-centring inputs and the device-memory estimate, packed the same way for both.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <cstdint>
#include <vector>

#include "filter/ensemble.h"
#include "host/common/device_options.h"
#include "host/mesh/observed_points.h"
#include "host/model/effects.h"
#include "host/model/model.h"
#include "host/model/so_history.h"
#include "step_constants.h"

namespace sigmafem {

// Estimated parameters a device ensemble takes at most (kernels/shared/step_constants.h).
constexpr int kDeviceMaxParameters = SF_MAX_PARAMETERS;

struct EnsembleTables {
  // Elements: element_nodes[4 e + c]; element_rest[16 e + i]: grad[12], vlambda, vmu, 0, 0.
  std::vector<int> element_nodes;
  std::vector<double> element_rest;
  // Node incidence (CSR): corners 4 e + c of node n, in element order, at
  // incidence[incidence_offsets[n] .. incidence_offsets[n + 1]). The node kernels gather in
  // this order: no atomics, the same sums every run.
  std::vector<int> incidence_offsets, incidence;
  // Ligaments on node n (CSR): ligament_of_node[ligament_offsets[n] .. [n + 1]).
  std::vector<int> ligament_offsets, ligament_of_node;
  // Per ligament and sigma point, N/m per node: ligament_k[l S + s] (at least one entry).
  std::vector<double> ligament_k;
  std::vector<double> control_k;        // per node, N/m (shared)
  std::vector<double> mass;             // per node, kg
  std::vector<double> rest_positions;   // 3 per node, m
  std::vector<double> initial_positions;  // the rest shape for every sigma point, 3N x S
};

// Checks an ensemble's arguments: std::invalid_argument naming `who`.
void check_ensemble_arguments(const Model& model, const std::vector<int>& estimated,
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

// The tables for S = sigma_count (after the device-memory check: they are as big as the
// per-sigma state).
EnsembleTables make_ensemble_tables(const Model& model, int sigma_count);

// Writes exp(theta(j, s)) / (nodes of ligament estimated[j]) into ligament_k (p x S theta).
void set_ligament_stiffness(const Model& model, const std::vector<int>& estimated,
                            const Eigen::MatrixXd& theta, int sigma_count,
                            std::vector<double>& ligament_k);

// The constants of each step of a device ensemble (kernels/shared/step_constants.h),
// SF_STEP_CONSTANTS + SF_SIGMA_CONSTANT_COUNT S numbers: the shared ones, then per sigma point
// s its gravity, SO target shift, the ligament law's 1/d0^2, Young's modulus scale and damping
// factors, from the model and the sigma point's physics effects (identity until set). Keeps
// the SO history the lags need.
class StepConstants {
 public:
  StepConstants(const Model& model, int sigma_count, double cg_tolerance);   // model: so(0), dt
  // One entry per sigma point (DeviceEnsemble::set_physics_effects); `who` names the caller
  // in the error for a wrong count.
  void set_physics_effects(const std::vector<PhysicsEffects>& effects, const std::string& who);
  // The constants of the next step of `model` (the one given at construction), whose SO is at
  // `so_position` at its end.
  std::vector<double> next_step(const Model& model, const Eigen::Vector3d& so_position);
  std::size_t size() const;

 private:
  std::vector<PhysicsEffects> physics_;
  SoHistory so_history_;
  double cg_tolerance_;
};

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

// Device memory of an ensemble, in bytes, for `real_size`-byte reals.
struct EnsembleMemory {
  std::size_t total = 0;     // about: all buffers
  std::size_t largest = 0;   // the largest single buffer (12 per element and sigma point)
};
EnsembleMemory ensemble_memory(int nodes, int elements, int sigma_count, std::size_t real_size);

// The "out of device memory" message: what the ensemble needs and what `device` has.
std::string out_of_device_memory_message(const EnsembleMemory& need, int elements,
                                         int sigma_count, const std::string& device,
                                         std::size_t device_memory, std::size_t largest_buffer);

}  // namespace sigmafem
