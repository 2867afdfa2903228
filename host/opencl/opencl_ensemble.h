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
#include <memory>
#include <vector>

#include "host/ensemble/device_ensemble.h"
#include "host/model/model.h"
#include "host/opencl/opencl_device.h"
#include "host/opencl/opencl_multigrid.h"
#include "host/reference/background_making.h"
#include "host/reference/factorised_preconditioner.h"
#include "host/reference/nested_multigrid.h"
#include "host/reference/refresh_rule.h"
#include "host/reference/spring_correction.h"

namespace sigmafem {

// The form of the kernels OpenClEnsemble builds on a device of this type ("cpu", "gpu", ...;
// OpenClDeviceInfo::type): `form`, or the device's own unless a test forces one.
bool opencl_cpu_form(KernelForm form, const std::string& device_type);
// Whether it preconditions CG with one shared factor: asked, or by default (automatic) on the
// CPU form, where it is faster on every case measured (bench/RESULTS.md, issue 18); not on
// the GPU form (the V-cycle or Jacobi there).
bool opencl_uses_factor(Preconditioner preconditioner, bool cpu_form);
// Whether it preconditions CG with the multigrid V-cycle (NestedMultigrid): asked, or by default
// on the GPU form where the mesh is a uniform refinement (`nested`: nested_prolongations() has
// a level), where it takes CG from hundreds of iterations to tens (bench/RESULTS.md, stop 54).
// Asked on the CPU form or on a mesh that was not refined so, the constructor throws.
bool opencl_uses_multigrid(Preconditioner preconditioner, bool cpu_form, bool nested);

class OpenClEnsemble : public DeviceEnsemble {
 public:
  // Elements x sigma points up to which a CPU device runs the whole CG solve in one launch.
  static constexpr long long kWholeSolveWork = 32768;
  // The vectors of each block of sigma points in cg_solve (x, b, the inverse diagonal, r, z,
  // d, q, the copy of K d), kept in element_out (SF_CG_SOLVE_VECTORS).
  static constexpr std::size_t kCgSolveBlockVectors = 8;

  // `estimated`: indices into model.ligaments whose log-stiffness the parameters are;
  // `observed`: the observed points (node indices convert). Throws DeviceError (no device,
  // build failure, too little memory).
  OpenClEnsemble(const Model& model, EstimatedParameters estimated, ObservedPoints observed,
                 int sigma_count, const DeviceOptions& options);
  ~OpenClEnsemble() override;   // waits for the writes still reading their host copies

  StepReport advance(const Eigen::Vector3d& so_position) override;
  void predicted_observations(Eigen::MatrixXd& y) const override;
  void recenter(const Recentering& recentering) override;
  const OpenClDeviceInfo& device_info() const { return device_.info(); }
  // Factorisations of the shared factor, or makings of the multigrid hierarchy, so far (0 with
  // Jacobi).
  int factorisations() const { return factor_ ? factor_makings_ : multigrid_makings_; }
  // Whether CG is preconditioned by the multigrid V-cycle.
  bool multigrid() const { return multigrid_ != nullptr; }

 private:
  std::vector<double> read_reals(DeviceBuffer buffer, std::size_t count) const override;
  void write_reals(DeviceBuffer buffer, const std::vector<double>& values) override;
  void write_integers(DeviceBuffer buffer, const int* data, std::size_t count);   // waits
  void upload_ligament_k() override;
  std::string device_name() const override { return device_.info().name; }
  void run_system_product() override;
  const cl::Buffer& buffer(DeviceBuffer id) const { return buffers_[static_cast<int>(id)]; }
  // Sets the kernel's arguments: `scalars` first, then its buffers (kernel_buffers()).
  template <class... Scalars>
  void set_arguments(cl::Kernel& kernel, const std::vector<DeviceBuffer>& buffers,
                     const Scalars&... scalars);

  // Enqueue the kernels of one step (kernels/opencl/<file>.cl holds the kernel of the same
  // name; conjugate_gradient() enqueues cg_start and cg_iteration).
  void run_elements(cl::Kernel& kernel) const;   // element_rhs, element_product: chunks or items
  void element_product(DeviceBuffer d, DeviceBuffer active);
  void node_product(DeviceBuffer d);   // A d from the element outputs, into q
  void conjugate_gradient();
  // With the multigrid V-cycle, z = M^-1 r in place of cg_start_partials' or cg_update's
  // Jacobi z, and the partial r.z again (cg_preconditioned; at the start also d = z).
  void precondition_outside(bool start);
  void run(cl::Kernel& kernel, std::size_t items, std::size_t local = 0) const;
  void run_cg(cl::Kernel& kernel) const;   // cg_start or cg_iteration, as SF_CG_PER_GROUP
  void run_partitions(cl::Kernel& kernel) const;   // a CG kernel's S x P groups (GPU form)
  // The observation gather and its read, not waited for.
  void enqueue_observations() const;
  // Makes the factor again from the representative (the mean sigma point), or each sigma
  // point's from its own system, when it is due, and uploads it; with no factor yet and a
  // system that is not positive definite, uploads the representative's diagonal instead
  // (upload_diagonal_factor). A large shared factor with one on the device already is made in
  // the background instead (preconditioner_making_), and upload_factor() runs at its hand-over.
  void refresh_factor(const std::vector<double>& constants);
  // The shared factor just made goes down (its values; its pattern the first time), with its
  // spring correction for `springs`, its system's springs at the correction's rows
  // (factorised_springs at the step it was made at).
  void upload_factor(const std::vector<double>& springs);
  // The factor's pattern and ordering, where the device has none yet (later ones keep them).
  void upload_factor_pattern();
  // The spring correction of a fresh shared factor (SpringCorrection): V at the rows it
  // reaches goes down, and its system's `springs` are kept for the couplings.
  void prepare_spring_correction(const std::vector<double>& springs);
  // Each sigma point's coupling H for its springs against the representative's.
  void upload_spring_coupling(const std::vector<double>& constants);
  // A stand-in for the factor: L = sqrt(|diag A|), no reordering, so that z = r / |diag A|,
  // Jacobi's preconditioner, until a factorisation succeeds.
  void upload_diagonal_factor(const Eigen::SparseMatrix<double>& A);
  // After a failed factorisation: the last factor stays; with none yet, A's diagonal goes down.
  void fall_back_to_diagonal(const Eigen::SparseMatrix<double>& A);
  // Makes the multigrid hierarchy again of the representative's system and uploads it; after a
  // failure the last one stays (none yet: Jacobi, from cg_update, for the step). With one on
  // the device already it is made in the background instead (preconditioner_making_).
  void refresh_multigrid(const std::vector<double>& constants);
  // The hierarchy just made goes down, with its system's `springs` at the estimated ligaments'
  // rows (factorised_springs at the step it was made at), against which the shifts are taken.
  void upload_multigrid(const std::vector<double>& springs);
  // At the step a background making is handed over: its factor or hierarchy goes down where it
  // was made (`made`); a failed one leaves the last in place.
  void hand_over_making(bool made);
  // Each sigma point's springs against the hierarchy's, the finest level's shift.
  void upload_multigrid_shift(const std::vector<double>& constants);

  mutable OpenClDevice device_;
  bool cg_per_group_ = true;                // SF_CG_PER_GROUP: CG kernels in work-groups (GPU)
  std::size_t cg_group_ = 64;               // SF_GROUP_SIZE: work-items per group then
  int sigma_block_ = 1;                     // SF_SIGMA_BLOCK: sigma points per element work-item
  int element_chunks_ = 0;                  // SF_ELEMENT_CHUNKS: the element kernels' chunks (CPU)
  bool whole_solve_ = false;                // cg_solve: the whole CG solve in one launch (CPU)
  int solve_block_ = 1;                     // SF_CG_SOLVE_BLOCK: cg_solve's sigma points per work-item
  int cg_block_ = 1;                        // SF_CG_BLOCK: sigma points per CG work-item (CPU)
  int cg_partitions_ = 1;                   // SF_CG_PARTITIONS: partitions of CG's rows (GPU)
  int cg_sigma_lanes_ = 1;                  // SF_CG_SIGMA_LANES: sigma points side by side in a group
  int cg_sigma_blocks_ = 1;                 // groups of cg_sigma_lanes_ sigma points: S / lanes, up
  // The GPU form's CG in the three kernels of the partitions (cg_dot, cg_update, cg_direction)
  // with P = cg_partitions_: on a large mesh, and with the multigrid V-cycle between the last two.
  bool cg_partitioned_ = false;
  std::vector<cl::Buffer> buffers_;         // by DeviceBuffer
  // Writes do not wait for the device (write_reals): each buffer's host copy is kept until
  // its write is done (the event), and the next read waits for them all. A wait on PoCL
  // hands the work to its threads and back, about 0.1 ms; a filter step wrote five times.
  std::vector<std::vector<unsigned char>> written_;   // by DeviceBuffer
  std::vector<cl::Event> write_done_;                 // by DeviceBuffer
  // The observations of the state advance() left, read back with its report (one wait
  // instead of two): valid until anything is written or re-centred.
  mutable std::vector<unsigned char> observation_bytes_;
  mutable bool observations_ready_ = false;
  // CG's preconditioner on the CPU form (opencl_uses_factor): sparse Cholesky factors (SF_FACTOR),
  // made on this one analysis; null: Jacobi.
  std::unique_ptr<FactorisedPreconditioner> factor_;
  // Copies of L's values: 1 (one factor of the mean sigma point, shared), or S (each sigma
  // point its own, of its own system: SF_FACTOR_PER_SIGMA; DeviceOptions::own_factors_bytes).
  int factor_copies_ = 1;
  // Sigma points per block of copies: entry k of sigma point s at
  // (s / block) nonzeros block + k block + s % block (factor_value_index).
  int factor_block_ = 1;
  std::size_t factor_value_index(int s, std::size_t k, std::size_t nonzeros) const;
  // The shared factor's correction for the sigma points' springs (no rows: none), the
  // representative's diagonal at its rows when factorised, and whether the couplings are out
  // of date.
  SpringCorrection springs_;
  std::vector<double> factorised_springs_;
  bool coupling_stale_ = false;
  // What the factor's buffers hold: nothing yet, the diagonal stand-in, or a factor (whose
  // pattern and ordering later refreshes keep).
  enum class FactorOnDevice { none, diagonal, factor };
  FactorOnDevice on_device_ = FactorOnDevice::none;
  int factor_makings_ = 0;   // successful factorisations (not read from factor_ while it is made)
  // CG's preconditioner on the GPU form where the mesh is a refinement (opencl_uses_multigrid):
  // the hierarchy of the representative's system, its copy on the device, its makings gone
  // down (0: none on the device yet), when to make it again, the estimated ligaments' rows
  // with the hierarchy's springs there, and whether the sigma points' shifts are out of date.
  std::unique_ptr<NestedMultigrid> multigrid_;
  std::unique_ptr<OpenClMultigrid> device_multigrid_;
  int multigrid_makings_ = 0;
  RefreshRule multigrid_refresh_;
  SpringCorrection shift_rows_;
  std::vector<double> multigrid_springs_;
  bool shift_stale_ = false;
  // A large shared factor, or the multigrid hierarchy, made again in the background
  // (DeviceOptions::background_making_steps), and its system's springs at the step it began
  // (the sigma points' parameters move on before the hand-over); factor_ or multigrid_ is the
  // making's until it is handed over. Declared after both: destroyed first, waiting for a
  // making still running.
  BackgroundMaking preconditioner_making_;
  std::vector<double> making_springs_;

  // Mutable: enqueueing a kernel (also from the const read-outs) changes no visible state.
  mutable cl::Kernel k_element_rhs_, k_node_rhs_, k_element_product_, k_node_product_;
  mutable cl::Kernel k_cg_start_, k_cg_iteration_, k_cg_solve_, k_state_update_;
  mutable cl::Kernel k_cg_start_partials_, k_cg_start_scalars_, k_cg_dot_, k_cg_update_;
  mutable cl::Kernel k_cg_direction_, k_cg_preconditioned_;
  mutable cl::Kernel k_observation_gather_;
  mutable cl::Kernel k_recenter_;
};

}  // namespace sigmafem
