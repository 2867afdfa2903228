// DeviceEnsemble: what the device back ends (OpenClEnsemble, VulkanEnsemble) have in common on
// the host: the model, the estimated ligaments and observed points, the per-step constants,
// the buffer table (host/ensemble/device_buffers.h) and the read-outs that let one
// conformance suite (tests/conformance/) check every back end against the CPU reference step by
// step: the rotations, the system product, one solve, whole trajectories. The read-outs copy
// device memory to the host; the filter never calls them. A back end adds its transfers and
// its launches.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "host/common/device_options.h"
#include "host/ensemble/device_buffers.h"
#include "host/ensemble/device_limits.h"
#include "host/ensemble/device_step_constants.h"
#include "host/ensemble/simulation_ensemble.h"
#include "host/mesh/observed_points.h"
#include "host/model/estimated_parameters.h"
#include "host/model/model.h"
#include "host/reference/factorised_preconditioner.h"
#include "host/reference/reference_simulation.h"
#include "host/reference/spring_correction.h"

namespace sigmafem {

class DeviceEnsemble : public SimulationEnsemble {
 public:
  int sigma_count() const override { return S_; }
  int parameter_count() const override { return estimated_.count(); }
  int observation_count() const override { return 3 * static_cast<int>(observed_.size()); }
  // The stiffnesses of the estimated ligaments from theta (p x S), for the next advance().
  void set_parameters(const Eigen::MatrixXd& theta) override;
  void set_physics_effects(const std::vector<PhysicsEffects>& effects) override;

  void read_states(Eigen::MatrixXd& positions, Eigen::MatrixXd& velocities) const override;
  void write_states(const Eigen::MatrixXd& positions, const Eigen::MatrixXd& velocities) override;
  // Sigma point s's positions and velocities, 3 per node (node-major, as the CPU reference).
  Eigen::VectorXd positions(int s) const;
  Eigen::VectorXd velocities(int s) const;
  // Sigma point s's element frames at the start of the last advance(), 9 per element.
  std::vector<double> frames(int s) const;
  // Column s of the result is A_s d_s, with A_s the implicit Euler matrix of sigma point s
  // at the last advance() (its frames and springs). d: 3N x S.
  Eigen::MatrixXd system_product(const Eigen::MatrixXd& d);
  // The CG tolerance the back end solves to (float32 back ends raise the scenario's).
  double cg_tolerance() const { return tolerance_; }
  // "opencl single on <device>", for messages and reports.
  std::string description() const;
  // Bytes of device memory the ensemble holds.
  std::size_t device_bytes() const { return device_bytes_; }

 protected:
  // `backend` ("opencl"), `who` ("OpenClEnsemble", for errors). Checks the arguments.
  DeviceEnsemble(const Model& model, EstimatedParameters estimated, ObservedPoints observed,
                 int sigma_count, Precision precision, const char* backend, const char* who);

  // Throws DeviceError when the ensemble needs more than `memory` bytes (or what
  // options.device_memory holds it to), or a buffer larger than `largest_buffer`, of device
  // `name` (ensemble_memory); keeps the device's figures for the checks below.
  void check_device_memory(const std::string& name, std::size_t memory, std::size_t largest_buffer,
                           const DeviceOptions& options);
  // The same check, on the device check_device_memory was given, with a shared factor's
  // buffers too.
  void check_device_memory_with_factor(std::size_t factor_nonzeros, FactorStorage storage,
                                       int factor_copies = 1) const;
  // Throws DeviceError when `more` bytes of buffers for `what`, made after the ensemble's own
  // (a multigrid hierarchy, known at its first making), would take the ensemble past the
  // memory check_device_memory was given.
  void check_more_device_memory(std::size_t more, const std::string& what) const;
  // The table of buffers with this back end's sizes (device_buffer_specs).
  // Also takes the model's stiffnesses into ligament_k_ (set_parameters() changes only the
  // estimated ligaments').
  std::vector<DeviceBufferSpec> buffer_specs(const DeviceBufferSizes& sizes);
  // The bytes of buffer `spec` with `real_size`-byte reals, counted into device_bytes_.
  std::size_t take_device_bytes(const DeviceBufferSpec& spec, std::size_t real_size);
  // CG's iterations after the start, checked on the host only now and then: `run_batch(count)`
  // runs `count` iterations and says whether a sigma point is still iterating. The first batch
  // is as long as the last step needed (warm-started steps need about the same), later ones
  // an eighth of that; a sigma point that is done is left alone by the kernels, so
  // overshooting changes nothing.
  template <class RunBatch>
  void iterate_in_batches(RunBatch run_batch) const {
    const int cap = model_.solver.cg_max_iterations;
    int batch = std::max(1, expected_iterations_);
    for (int done = 0; done < cap;) {
      const int count = std::min(batch, cap - done);
      done += count;
      if (!run_batch(count)) break;
      batch = std::max(2, expected_iterations_ / 8);
    }
  }
  // The representative's implicit-Euler matrix at state (x, v), assembled on the host: what
  // a factor shared by the sigma points is made of. The representative has the sigma points'
  // mean log-stiffnesses (the filter's estimate) and sigma point 0's effects; measured on
  // the liver's filter step (S = 4), its factor took 5.5 CG iterations a step where sigma
  // point 0's took 7.2.
  Eigen::SparseMatrix<double> representative_system(const Eigen::VectorXd& x,
                                                    const Eigen::VectorXd& v) const;
  // Sigma point s's own matrix at its state (x, v): its parameters and effects (a factor of
  // its own, OpenCL's CPU form on small meshes).
  Eigen::SparseMatrix<double> sigma_system(int s, const Eigen::VectorXd& x, const Eigen::VectorXd& v) const;
  // The same at the sigma points' mean state.
  Eigen::SparseMatrix<double> representative_system() const;
  // ... its inputs (the mean state, the parameters, the effects) read now and the matrix
  // assembled when called: on a background making's thread (host/reference/background_making.h),
  // so that the step that starts it does not stop for the assembly (8 ms on the 38k liver, 35
  // on the 117k box here: bench/multigrid_making_bench.cpp).
  // The representative simulation it assembles with must not be used elsewhere meanwhile.
  std::function<Eigen::SparseMatrix<double>()> representative_system_later() const;
  // ligament_k_ with every sigma point's estimated ligaments at the representative's
  // stiffnesses (the sigma points' mean log-stiffnesses, as representative_system has them).
  std::vector<double> representative_ligament_k() const;
  // A factor shared by the sigma points (OpenCL's CPU form, Vulkan on a CPU device), analysed
  // on the representative's system at rest: its size is known before the first step makes it.
  // With `springs`' rows ordered last, where it is corrected for them (FactorisedPreconditioner).
  std::unique_ptr<FactorisedPreconditioner> analysed_factor(const SpringCorrection& springs = SpringCorrection()) const;
  // Its correction for the sigma points' springs (SpringCorrection) at the estimated
  // ligaments' rows, where `asked` and m x S stays small (spring_correction_fits); else none.
  SpringCorrection spring_correction(bool asked) const;
  // The springs of the factor's system at the correction's rows (the representative's, with
  // sigma point 0's stiffness factor: its effects, as representative_system has them) ...
  std::vector<double> factorised_springs(const SpringCorrection& springs, const std::vector<double>& constants) const;
  // ... and each sigma point's coupling H for its own springs (ligament_k_) against them:
  // [(s m + j) m + k], S m^2 reals.
  std::vector<double> spring_couplings(const SpringCorrection& springs, const std::vector<double>& constants,
                                       const std::vector<double>& factorised) const;
  // ... and each sigma point's springs there less them (what the multigrid's finest level adds
  // per sigma point): [j S + s].
  std::vector<double> spring_shifts(const SpringCorrection& springs, const std::vector<double>& constants,
                                    const std::vector<double>& factorised) const;
  // The same at every one of the 3N rows, zero off the springs' rows: [row S + s].
  std::vector<double> spring_shift_rows(const SpringCorrection& springs, const std::vector<double>& constants,
                                        const std::vector<double>& factorised) const;
  // The step's solver report from CG's per-sigma results; notes the iterations for the next
  // step's first batch.
  StepReport step_report(const std::vector<std::int32_t>& iterations,
                         const std::vector<std::uint32_t>& converged, const std::vector<double>& rr,
                         const std::vector<double>& bb);

  // The back end's transfers: `count` reals of a buffer; the stiffnesses (ligament_k_) for
  // the next step; the device's name; A d of the `d` buffer into `q` (system_product).
  virtual std::vector<double> read_reals(DeviceBuffer buffer, std::size_t count) const = 0;
  virtual void write_reals(DeviceBuffer buffer, const std::vector<double>& values) = 0;
  virtual void upload_ligament_k() = 0;
  virtual std::string device_name() const = 0;
  virtual void run_system_product() = 0;

  Model model_;                   // a copy: the ensemble outlives its caller's model
  EstimatedParameters estimated_;
  ObservedPoints observed_;
  int S_ = 0, nodes_ = 0, elements_ = 0;
  Precision precision_;
  double tolerance_ = 0.0;
  StepConstants step_constants_;  // per step, with the per-sigma effects
  std::vector<double> ligament_k_;   // per ligament and sigma, N/m per node: [l S + s]
  std::size_t device_bytes_ = 0;
  // check_device_memory's device: its usable memory, largest buffer and name for messages.
  std::size_t device_memory_ = 0, largest_buffer_ = 0;
  std::string device_name_;
  int expected_iterations_ = 1;   // CG iterations the last step needed (at most)
  // Whether the kernels keep only each frame's first two rows (Vulkan: kernels/vulkan/
  // ensemble_layout.h's SF_FRAME_ROWS_KEPT); frames() then makes the third as they do. Set
  // before the memory checks and the buffers: their size per element and sigma point.
  bool frames_keep_two_rows_ = false;
  std::size_t frame_numbers() const;   // DeviceBufferSizes::frame_numbers
  const char* backend_;
  const char* who_;

 private:
  std::vector<double> column_of(DeviceBuffer buffer, std::size_t rows, int s) const;
  // h (h + a) times the estimated ligaments' springs at each of `springs`' rows, for sigma
  // point s of the step's constants and stiffnesses ligament_k ([l S + s]).
  std::vector<double> spring_diagonal(const SpringCorrection& springs, const std::vector<double>& constants,
                                      int s, const std::vector<double>& ligament_k) const;
  Eigen::MatrixXd theta_;                       // each sigma point's parameters (none yet: the model's)
  std::vector<PhysicsEffects> effects_;         // and effects (none yet: none)
  // The implicit-Euler matrix of parameters `theta` (empty: the model's) and `effects` at
  // state (x, v), assembled on the host by the representative simulation.
  Eigen::SparseMatrix<double> system_at(const Eigen::VectorXd& theta, const PhysicsEffects& effects,
                                        const Eigen::VectorXd& x, const Eigen::VectorXd& v) const;
  mutable std::unique_ptr<ReferenceSimulation> representative_;   // keeps its assembly pattern
};

}  // namespace sigmafem
