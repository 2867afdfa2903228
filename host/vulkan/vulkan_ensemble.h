// VulkanEnsemble: the Ensemble (filter/ensemble.h) with all S sigma-point simulations
// advancing together in Vulkan compute shaders (kernels/vulkan/, named as the OpenCL kernels
// of kernels/opencl/), behind the same DeviceEnsemble interface as OpenClEnsemble, with the
// same buffers (host/ensemble/device_buffers.h) and the same deterministic assembly (a
// per-node gather in a fixed order, fixed-tree reductions; no float atomics).
//
// A step is recorded into command buffers, not enqueued kernel by kernel: the right-hand
// side, the warm start and a first batch of CG iterations (as many as the last step needed)
// in one, then more batches if some sigma point is still iterating (the host reads the S
// active flags after each), then the state update with the observation gather. Typically
// two host waits per step; predicted_observations() then reads what the step gathered.
// set_parameters() and recenter() wait for nothing: what they write (the stiffnesses, the
// re-centring's inputs and its dispatch) is recorded at the head of the next command buffer
// (until stop 41 each wrote with its own submission: seven host waits per filter step).
//
// Arithmetic and tolerances as OpenClEnsemble: float32 by default, the CG tolerance raised
// to kSingleCgTolerance; --precision double needs shaderFloat64. CG's preconditioner: on a
// CPU device OpenCL's shared factor corrected for each sigma point's springs
// (VulkanFactorSolve), on a GPU the multigrid V-cycle where the mesh is a refinement
// (VulkanMultigrid), else Jacobi (vulkan_uses_factor, vulkan_uses_multigrid).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "device_layout.h"
#include "host/ensemble/device_ensemble.h"
#include "host/model/model.h"
#include "host/reference/background_making.h"
#include "host/reference/factorised_preconditioner.h"
#include "host/vulkan/vulkan_device.h"
#include "host/vulkan/vulkan_factor_solve.h"
#include "host/vulkan/vulkan_multigrid.h"
#include "host/reference/nested_multigrid.h"
#include "host/reference/refresh_rule.h"
#include "host/vulkan/vulkan_push_constants.h"

namespace sigmafem {

// The form of the Vulkan shaders: the CPU form reads the arrays a shader only reads through
// uniform texel buffers (lavapipe gathers them 3-5x faster than storage-buffer loads:
// kernels/vulkan/ensemble_layout.h), the GPU form through storage buffers. Automatic is the
// CPU form on a CPU device. Texel reads need every buffer within the device's texel limit
// (largest_bytes / 4 <= max_texel_elements); without that, the GPU form.
bool vulkan_texel_reads(KernelForm form, const std::string& device_type,
                        std::size_t largest_bytes, unsigned long long max_texel_elements);

// Whether Vulkan preconditions CG with one shared factor (VulkanFactorSolve): asked, or by
// default on a CPU device (lavapipe), where fewer iterations save more dispatches than the
// substitutions cost; not on a GPU, where a lane per sigma point in a sequential solve would
// leave it idle (the V-cycle or Jacobi there).
bool vulkan_uses_factor(Preconditioner preconditioner, const std::string& device_type);
// Whether it preconditions CG with the multigrid V-cycle (VulkanMultigrid): asked, or by
// default on a GPU where the mesh is a uniform refinement (`nested`: nested_prolongations()
// has a level), as OpenCL's GPU form. Asked on a mesh that was not refined so, the
// constructor throws.
bool vulkan_uses_multigrid(Preconditioner preconditioner, const std::string& device_type, bool nested);
// The CG shaders' lanes over sigma points with one partition on a CPU device
// (conjugate_gradient.comp's SF_LANE_ROWS: rows at once a sigma point): 1 from `lanes_from`
// sigma points (DeviceOptions::cg_sigma_lanes_from; 0: never); with the factor and 8-lane
// subgroup shuffles at S <= 4, 8 / S rounded down to a power of 2 (2 at S = 3-4, 4 at 2, 8 at 1);
// else 0, a work-group a sigma point.
int cg_lane_rows(int lanes_from, int sigma_count, const VulkanDeviceInfo& info, bool one_partition, bool factor);
// The loop turns of the CG shaders' busiest invocation when their lanes walk every `row_step`-th
// node of a sigma point's partition (J with lanes over sigma points, else the group size; the
// nodes cut into `partitions` as the shaders cut them): at
// each node cg_node_iteration, the busiest, turns once per element corner and ligament there
// and kCgNodeTurns more (the node loops of its d.q and its update, 3 rows each), and lanes that
// run in one vector turn together, as often as their busiest node needs (an upper bound: the
// busiest of the row_step nodes taken at once). llvmpipe ends every loop of an invocation past
// 65535 turns (kShaderLoopTurns), silently: before this bound the 38k liver's CG at S = 4 (2
// lanes a sigma point, ~115 000 turns) started from a residual with its last rows never written.
constexpr long long kCgNodeTurns = 8;
long long cg_loop_turns(const Model& model, int row_step, int partitions = 1);
// The same from each node's turns (cg_node_turns: its corners, ligaments and kCgNodeTurns), made
// once where several steps are tried.
std::vector<long long> cg_node_turns(const Model& model);
long long cg_loop_turns(const std::vector<long long>& node_turns, int row_step, int partitions = 1);

class VulkanEnsemble : public DeviceEnsemble {
 public:
  // `estimated`: indices into model.ligaments whose log-stiffness the parameters are;
  // `observed`: the observed points (node indices convert). Throws DeviceError (no device,
  // shader failure, too little memory).
  VulkanEnsemble(const Model& model, EstimatedParameters estimated, ObservedPoints observed,
                 int sigma_count, const DeviceOptions& options);

  StepReport advance(const Eigen::Vector3d& so_position) override;
  void predicted_observations(Eigen::MatrixXd& y) const override;
  void recenter(const Recentering& recentering) override;
  const VulkanDeviceInfo& device_info() const { return device_.info(); }
  // Whether the shaders read their read-only arrays through texel buffers (the CPU form).
  bool texel_reads() const { return device_.texel_reads(); }
  // Whether a CG iteration is two dispatches (cg_node_iteration forms q = A d), not three.
  bool node_iteration() const { return node_iteration_; }
  // Whether the element shaders take four sigma points a lane (kernels/vulkan/sigma_quads.h).
  bool sigma_quads() const { return sigma_quads_; }
  // Whether the CG shaders take sigma points side by side (conjugate_gradient.comp): rows
  // (nodes) at once of each sigma point's lanes in them; 0: a work-group a sigma point (or
  // partition). One partition on a CPU device (DeviceOptions::cg_sigma_lanes_from), the
  // partitions' shaders on a GPU (CgGroups, DeviceOptions::cg_sigma_lanes).
  int cg_lane_rows() const { return cg_lane_rows_; }
  // CG's work-groups a sigma point (or a block of sigma points side by side).
  int cg_partitions() const { return cg_partitions_; }
  // Work-items per sigma point (or partition) in the CG shaders without lanes over sigma points
  // (specialization constant 0): 8 on a CPU device, 64 on a GPU, more where a mesh's nodes would
  // turn their loops too often.
  std::uint32_t cg_group_size() const { return cg_group_; }
  // Host waits (command-buffer submissions) of the last advance().
  int last_step_waits() const { return last_step_waits_; }
  // Whether CG is preconditioned by a factor (vulkan_uses_factor), its factorisations so far
  // (0 with Jacobi), and the dispatches of one solve with it.
  bool factorised() const { return factor_ != nullptr; }
  std::size_t factor_nonzeros() const { return factor_ ? factor_->nonzeros() : 0; }   // 0: none
  int factorisations() const { return factor_ ? factor_makings_ : multigrid_makings_; }
  // Whether CG is preconditioned by the multigrid V-cycle (its makings: factorisations()).
  bool multigrid() const { return multigrid_ != nullptr; }
  int factor_solve_dispatches() const { return factor_solve_ ? factor_solve_->dispatches() : 0; }

 private:
  using PushConstants = VulkanPushConstants;
  std::vector<double> read_reals(DeviceBuffer buffer, std::size_t count) const override;
  void write_reals(DeviceBuffer buffer, const std::vector<double>& values) override;
  void upload_ligament_k() override;
  std::string device_name() const override { return device_.info().name; }
  void run_system_product() override;
  const VulkanBuffer& buffer(DeviceBuffer id) const { return buffers_[static_cast<int>(id)]; }
  // A descriptor set of `kernel` with `buffers` at bindings 0, 1, ...
  VkDescriptorSet bind(const VulkanKernel& kernel, const std::vector<DeviceBuffer>& buffers);

  // Recording (kernels/vulkan/<file>.comp holds the shader of the same name).
  void dispatch_items(VkCommandBuffer cmd, const VulkanKernel& kernel, VkDescriptorSet set,
                      std::size_t items, std::uint32_t count) const;
  void record_cg_iterations(VkCommandBuffer cmd, int count) const;
  // Makes the factor again from the representative (the mean sigma point) when it is due and
  // uploads it with its spring correction; with no factor yet and a failed factorisation,
  // A's diagonal (Jacobi) instead.
  // A large factor (DeviceOptions::background_making_solves) with one on the device already is
  // made in the background instead (preconditioner_making_), and upload_factor() runs at its
  // hand-over.
  void refresh_factor(const std::vector<double>& constants);
  // The factor just made goes down with its spring correction for `springs`, its system's
  // springs at the correction's rows (factorised_springs at the step it was made at).
  void upload_factor(const std::vector<double>& springs);
  // Makes the multigrid hierarchy again of the representative's system and uploads it; after
  // a failure the last one stays (none yet: Jacobi, cg_update's z, for the step). With one on
  // the device already it is made in the background instead (preconditioner_making_).
  void refresh_multigrid(const std::vector<double>& constants);
  // The hierarchy just made goes down, with its system's `springs` at the estimated ligaments'
  // rows (factorised_springs at the step it was made at), against which the shifts are taken.
  void upload_multigrid(const std::vector<double>& springs);
  // At the step a background making is handed over: its factor or hierarchy goes down where it
  // was made (`made`); a failed one leaves the last in place.
  void hand_over_making(bool made);
  // With the V-cycle: z = M^-1 r over Jacobi's, then cg_preconditioned (r.z; at the start d = z).
  void record_multigrid(VkCommandBuffer cmd, bool start) const;
  void record_system_product(VkCommandBuffer cmd, VkDescriptorSet element_product_set) const;
  // Lanes of the element shaders: elements x S, or x S / 4 with sigma quads.
  std::size_t element_items() const;
  // Lanes of the node shaders: nodes x S, or x S / 4 with sigma quads.
  std::size_t node_items() const;
  // Work-groups of the CG shaders: S x partitions, or with lanes over sigma points J S / cg_group_
  // (rounded up).
  std::uint32_t cg_groups() const;
  // Records what set_parameters() and recenter() left for the next submission; flush_pending()
  // submits it alone, before a read-out.
  bool has_pending() const;
  void record_pending(VkCommandBuffer cmd) const;
  void flush_pending() const;

  mutable VulkanDevice device_;
  std::uint32_t cg_group_ = 64;              // work-items per sigma point in the CG shaders
  int cg_partitions_ = 1;                    // work-groups per sigma point in them (constant 1)
  bool node_iteration_ = false;              // CG iterations by element_product and cg_node_iteration
  bool sigma_quads_ = false;                 // element and node shaders four sigma points a lane
  bool cg_partitioned_ = false;              // CG in the partitions' shaders (P > 1, or the V-cycle)
  int cg_lane_rows_ = 0;                     // the CG shaders' lanes a sigma point (constant 2; cg_lane_rows())
  int last_step_waits_ = 0;
  // The observations gathered at the end of the last advance(), until recenter() moves x.
  mutable std::vector<double> observations_cache_;
  mutable bool observations_current_ = false;
  // The recenter shader made for S and p (its specialization constants; made again when a
  // re-centring comes with another p, as from an EffectEnsemble's added parameters).
  void make_recenter(std::uint32_t p);
  std::uint32_t recenter_parameters_ = 0;
  // Device reals waiting for the next command buffer (record_pending): the stiffnesses, and
  // the re-centring's inputs with its dispatch.
  mutable std::vector<unsigned char> pending_ligament_k_;
  mutable std::vector<unsigned char> pending_scalars_, pending_directions_, pending_weights_;
  mutable bool pending_recenter_ = false;
  std::vector<VulkanBuffer> buffers_;        // by DeviceBuffer

  VulkanKernel k_element_rhs_, k_node_rhs_, k_element_product_, k_node_product_;
  VulkanKernel k_cg_start_, k_cg_iteration_, k_state_update_, k_observation_gather_, k_recenter_;
  VulkanKernel k_cg_start_partials_, k_cg_start_scalars_, k_cg_dot_, k_cg_update_, k_cg_direction_;
  VulkanKernel k_cg_node_iteration_, k_cg_preconditioned_;
  // CG's shared factor (vulkan_uses_factor), with its refresh rule, and its solve on the device.
  std::unique_ptr<FactorisedPreconditioner> factor_;
  std::unique_ptr<VulkanFactorSolve> factor_solve_;
  // The factor's correction for each sigma point's springs (no rows: none), the factor's
  // system's springs at its rows, and whether the couplings are out of date.
  SpringCorrection springs_;
  std::vector<double> factorised_springs_;
  bool coupling_stale_ = false;
  int factor_makings_ = 0;   // successful factorisations (not read from factor_ while it is made)
  // The GPU form's multigrid V-cycle (vulkan_uses_multigrid): the hierarchy of the
  // representative's system, its dispatches, when to make it again, the estimated ligaments'
  // rows with the hierarchy's springs there, and whether the sigma points' shifts are stale.
  std::unique_ptr<NestedMultigrid> multigrid_;
  std::unique_ptr<VulkanMultigrid> multigrid_solve_;
  RefreshRule multigrid_refresh_;
  int multigrid_makings_ = 0;
  SpringCorrection shift_rows_;
  std::vector<double> multigrid_springs_;
  bool shift_stale_ = false;
  // A large factor, or the multigrid hierarchy, made again in the background (as
  // OpenClEnsemble's; declared after factor_ and multigrid_: destroyed first, waiting for a
  // making still running), and its system's springs at the step it began.
  BackgroundMaking preconditioner_making_;
  std::vector<double> making_springs_;
  // Descriptor sets; element_product has three: the warm start's product (dv, all active),
  // the CG product (d, the active flags) and system_product()'s (d, all active).
  VkDescriptorSet s_element_rhs_ = VK_NULL_HANDLE, s_node_rhs_ = VK_NULL_HANDLE;
  VkDescriptorSet s_product_warm_start_ = VK_NULL_HANDLE, s_product_cg_ = VK_NULL_HANDLE;
  VkDescriptorSet s_product_all_ = VK_NULL_HANDLE, s_node_product_ = VK_NULL_HANDLE;
  VkDescriptorSet s_cg_start_ = VK_NULL_HANDLE, s_cg_iteration_ = VK_NULL_HANDLE;
  VkDescriptorSet s_state_update_ = VK_NULL_HANDLE, s_observation_gather_ = VK_NULL_HANDLE;
  VkDescriptorSet s_recenter_ = VK_NULL_HANDLE;
  VkDescriptorSet s_cg_start_partials_ = VK_NULL_HANDLE, s_cg_start_scalars_ = VK_NULL_HANDLE;
  VkDescriptorSet s_cg_dot_ = VK_NULL_HANDLE, s_cg_update_ = VK_NULL_HANDLE;
  VkDescriptorSet s_cg_direction_ = VK_NULL_HANDLE, s_cg_node_iteration_ = VK_NULL_HANDLE;
  VkDescriptorSet s_cg_preconditioned_ = VK_NULL_HANDLE;
};

}  // namespace sigmafem
