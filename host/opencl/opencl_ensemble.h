// OpenClEnsemble: the Ensemble (filter/ensemble.h) with all S sigma-point simulations
// advancing together in OpenCL kernels (kernels/opencl/, one file per step, named as the
// methods below that enqueue them). The state of every sigma point stays on the device; per
// filter step only the S parameter vectors go down and the observed positions (3m x S) and
// the solver report come back. Layout and assembly: kernels/opencl/ensemble_layout.h.
//
// Arithmetic is float32 by default. float32 cannot reach the scenario's CG tolerance (1e-10
// is far below its rounding), so in single precision the tolerance is raised to
// kSingleCgTolerance; double precision keeps the scenario's and agrees with the CPU reference
// to about 1e-10 (tests/opencl/).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "host/ensemble/device_ensemble.h"
#include "host/ensemble/ensemble_tables.h"
#include "host/model/model.h"
#include "host/opencl/opencl_device.h"

namespace sigmafem {

class OpenClEnsemble : public DeviceEnsemble {
 public:
  // Elements x sigma points up to which a CPU device runs the whole CG solve in one launch.
  static constexpr long long kWholeSolveWork = 32768;

  // `estimated`: indices into model.ligaments whose log-stiffness the parameters are;
  // `observed`: the observed points (node indices convert). Throws DeviceError (no device, build failure, too little memory).
  OpenClEnsemble(const Model& model, std::vector<int> estimated, ObservedPoints observed,
                 int sigma_count, const DeviceOptions& options);

  int sigma_count() const override { return S_; }
  int parameter_count() const override { return static_cast<int>(estimated_.size()); }
  int observation_count() const override { return 3 * static_cast<int>(observed_.size()); }
  void set_parameters(const Eigen::MatrixXd& theta) override;
  StepReport advance(const Eigen::Vector3d& so_position) override;
  void predicted_observations(Eigen::MatrixXd& y) const override;
  void recenter(const Recentering& recentering) override;

  // DeviceEnsemble's read-outs (tests, VTK output).
  Eigen::VectorXd positions(int s) const override;
  Eigen::VectorXd velocities(int s) const override;
  std::vector<double> frames(int s) const override;
  Eigen::MatrixXd system_product(const Eigen::MatrixXd& d) override;
  double cg_tolerance() const override { return tolerance_; }
  std::string description() const override;
  void set_physics_effects(const std::vector<PhysicsEffects>& effects) override;
  const OpenClDeviceInfo& device_info() const { return device_.info(); }
  // Bytes of device memory the ensemble holds.
  std::size_t device_bytes() const { return device_bytes_; }

 private:
  cl::Buffer make_buffer(std::size_t count, const char* what);
  cl::Buffer make_buffer(const std::vector<double>& values, const char* what);
  cl::Buffer make_buffer(const std::vector<int>& values, const char* what);
  void write(const cl::Buffer& buffer, const std::vector<double>& values) const;
  std::vector<double> read(const cl::Buffer& buffer, std::size_t count) const;
  // Sigma point s's column of a per-row buffer (host/ensemble/device_readout.h).
  std::vector<double> column_of(const cl::Buffer& buffer, std::size_t rows, int s) const;
  void write_step_constants(const Eigen::Vector3d& so_position);

  // Enqueue the kernels of one step (kernels/opencl/<file>.cl holds the kernel of the same
  // name; conjugate_gradient() enqueues cg_start and cg_iteration).
  std::size_t element_items() const;   // work-items of the element kernels
  void element_rhs();
  void node_rhs();
  void element_product(const cl::Buffer& d, const cl::Buffer& active);
  void node_product(const cl::Buffer& d, const cl::Buffer& q);
  void conjugate_gradient();
  void run(cl::Kernel& kernel, std::size_t items, std::size_t local = 0) const;
  void run_cg(cl::Kernel& kernel) const;   // cg_start or cg_iteration, as SF_CG_PER_GROUP
  void run_partitions(cl::Kernel& kernel) const;   // a CG kernel's S x P groups (GPU form)

  mutable OpenClDevice device_;
  Model model_;                             // a copy: the ensemble outlives its caller's model
  StepConstants step_constants_;            // per step, with the per-sigma effects
  std::vector<int> estimated_;
  ObservedPoints observed_;
  int S_ = 0, nodes_ = 0, elements_ = 0;
  double tolerance_ = 0.0;
  std::size_t device_bytes_ = 0;
  std::vector<double> ligament_k_;          // per ligament and sigma, N/m per node: [l * S + s]
  bool cg_per_group_ = true;                // SF_CG_PER_GROUP: CG kernels a group per sigma (GPU)
  std::size_t cg_group_ = 64;               // SF_GROUP_SIZE: work-items per sigma point then
  int sigma_block_ = 1;                     // SF_SIGMA_BLOCK: sigma points per element work-item
  int element_chunks_ = 0;                  // SF_ELEMENT_CHUNKS: element_product's chunks (CPU)
  int expected_iterations_ = 1;             // CG iterations the last step needed (at most)
  bool whole_solve_ = false;                // cg_solve: the whole CG solve in one launch (CPU)
  int cg_block_ = 1;                        // SF_CG_BLOCK: sigma points per CG work-item (CPU)
  int cg_partitions_ = 1;                   // SF_CG_PARTITIONS: CG work-groups per sigma (GPU)

  // Shared data.
  cl::Buffer element_nodes_, element_rest_, incidence_offsets_, incidence_;
  cl::Buffer ligament_offsets_, ligament_of_node_, control_k_, mass_, rest_positions_;
  cl::Buffer observed_nodes_, observed_weights_, constants_;
  // Per-sigma data.
  cl::Buffer ligament_k_buffer_, x_, v_, dv_, rhs_, inverse_diagonal_, r_, z_, d_, q_;
  cl::Buffer frames_, element_out_, element_diagonal_, observations_;
  // Per-sigma CG scalars; all_active_ holds S ones (products outside CG).
  cl::Buffer bb_, rr_, rz_, active_, converged_, iterations_, all_active_;
  // With partitions: the partial sums, and each (sigma, partition) group's own scalars.
  cl::Buffer partial_, own_active_, own_iterations_, own_rz_;
  // Re-centring inputs.
  cl::Buffer recenter_scalars_, directions_, weights_;

  // Mutable: enqueueing a kernel (also from the const read-outs) changes no visible state.
  mutable cl::Kernel k_element_rhs_, k_node_rhs_, k_element_product_, k_node_product_;
  mutable cl::Kernel k_cg_start_, k_cg_iteration_, k_cg_solve_, k_state_update_;
  mutable cl::Kernel k_cg_start_partials_, k_cg_start_scalars_, k_cg_dot_, k_cg_update_;
  mutable cl::Kernel k_cg_direction_;
  mutable cl::Kernel k_observation_gather_;
  mutable cl::Kernel k_recenter_;
};

}  // namespace sigmafem
