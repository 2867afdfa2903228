#include "host/vulkan/vulkan_ensemble.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include "host/ensemble/device_readout.h"
#include "host/ensemble/device_limits.h"

namespace sigmafem {
namespace {

std::uint32_t groups_for(std::size_t items) {
  return static_cast<std::uint32_t>((items + SF_ITEMS_PER_GROUP - 1) / SF_ITEMS_PER_GROUP);
}

}  // namespace

bool vulkan_texel_reads(KernelForm form, const std::string& device_type,
                        std::size_t largest_bytes, unsigned long long max_texel_elements) {
  const bool cpu_form = form == KernelForm::cpu || (form == KernelForm::automatic && device_type == "cpu");
  return cpu_form && largest_bytes / 4 <= max_texel_elements;
}

bool vulkan_uses_factor(Preconditioner preconditioner, const std::string& device_type) {
  return preconditioner == Preconditioner::factorised ||
         (preconditioner == Preconditioner::automatic && device_type == "cpu");
}

bool vulkan_uses_multigrid(Preconditioner preconditioner, const std::string& device_type, bool nested) {
  return preconditioner == Preconditioner::multigrid ||
         (preconditioner == Preconditioner::automatic && device_type != "cpu" && nested);
}

int cg_lane_rows(int lanes_from, int sigma_count, const VulkanDeviceInfo& info, bool one_partition, bool factor) {
  if (info.type != "cpu" || !one_partition || lanes_from <= 0 || sigma_count <= 0) return 0;
  if (sigma_count >= lanes_from) return 1;
  if (!factor || !info.shuffles_groups_of(8) || sigma_count > 4) return 0;
  int rows = 1;
  while (2 * rows * sigma_count <= 8) rows *= 2;
  return rows;
}

std::vector<long long> cg_node_turns(const Model& model) {
  std::vector<long long> turns(static_cast<std::size_t>(model.node_count()), kCgNodeTurns);
  for (const ElementRest& element : model.elements)
    for (const int n : element.nodes) ++turns[static_cast<std::size_t>(n)];
  for (const SpringSet& ligament : model.ligaments)
    for (const int n : ligament.nodes) ++turns[static_cast<std::size_t>(n)];
  return turns;
}

long long cg_loop_turns(const std::vector<long long>& turns, int row_step, int partitions) {
  const int nodes = static_cast<int>(turns.size());
  const int step = std::max(1, row_step);
  // Partition p's nodes as conjugate_gradient.comp's sf_partition_nodes cuts them.
  const int size = (nodes + std::max(1, partitions) - 1) / std::max(1, partitions);
  long long busiest = 0;
  for (int begin = 0; begin < nodes; begin += size) {
    const int end = std::min(nodes, begin + size);
    long long total = 0;
    for (int first = begin; first < end; first += step)
      total += *std::max_element(turns.begin() + first, turns.begin() + std::min(end, first + step));
    busiest = std::max(busiest, total);
  }
  return busiest;
}

long long cg_loop_turns(const Model& model, int row_step, int partitions) {
  return cg_loop_turns(cg_node_turns(model), row_step, partitions);
}

VulkanEnsemble::VulkanEnsemble(const Model& model, EstimatedParameters estimated,
                               ObservedPoints observed, int sigma_count,
                               const DeviceOptions& options)
    : DeviceEnsemble(model, std::move(estimated), std::move(observed), sigma_count,
                     options.precision, "vulkan", "VulkanEnsemble"),
      device_(options.device, options.precision,
              static_cast<long long>(model.element_count()) * sigma_count < options.lavapipe_serial_work) {
  // Check the memory before asking for it, to say how much is needed.
  const VulkanDeviceInfo& info = device_.info();
  frames_keep_two_rows_ = true;   // element_rhs stores two rows of each frame (ensemble_layout.h)
  check_device_memory(info.name, info.memory, info.max_buffer, options);
  // Work-items per sigma point in CG: on a CPU (lavapipe) one SIMD register's worth, so that
  // a group's barriers cost nothing; on a GPU 64 (two warps, one wavefront).
  cg_group_ = info.type == "cpu" ? 8 : 64;
  // CG's work-groups per sigma point (conjugate_gradient.comp): by the mesh on a GPU, with
  // sigma points side by side in them (CgGroups, as OpenCL's GPU form), one on a CPU (lavapipe),
  // where S groups already keep its few cores busy, unless a test forces them.
  CgGroups groups;
  if (info.type != "cpu" || options.cg_partitions > 0)
    groups = sigmafem::cg_groups(nodes_, S_, real_size(options.precision), static_cast<int>(cg_group_),
                                 options.cg_partitions, options.cg_sigma_lanes);
  cg_partitions_ = groups.partitions;
  // The CG shaders take ceil(S / lanes) x partitions work-groups along x.
  const std::uint64_t sigma_blocks = (static_cast<std::uint64_t>(S_) + groups.sigma_lanes - 1) / groups.sigma_lanes;
  if (sigma_blocks * cg_partitions_ > device_.max_group_count())
    throw DeviceError("Vulkan device " + info.name + " runs at most " +
                      std::to_string(device_.max_group_count() / cg_partitions_ * groups.sigma_lanes) +
                      " sigma points on this mesh");
  // The multigrid V-cycle on a GPU, on the refinements that made the mesh.
  std::vector<RowMajorMatrix> prolongations;
  if (options.preconditioner == Preconditioner::multigrid ||
      (options.preconditioner == Preconditioner::automatic && info.type != "cpu"))
    prolongations = nested_prolongations(model_);
  if (vulkan_uses_multigrid(options.preconditioner, info.type, !prolongations.empty())) {
    if (prolongations.empty())
      throw DeviceError("--preconditioner multigrid: the mesh is not a uniform refinement of a coarser one "
                        "(a scenario's mesh.refine makes one)");
    multigrid_ = std::make_unique<NestedMultigrid>(std::move(prolongations));
    shift_rows_ = SpringCorrection(estimated_spring_rows(model_, estimated_));
    multigrid_refresh_.fix_cost(options.multigrid_making_cycles);
    preconditioner_making_.set_rule(options.background_making_steps, kBackgroundMultigridCycles);
  }
  cg_partitioned_ = cg_partitions_ > 1 || multigrid_;
  // CG's preconditioner (vulkan_uses_factor): one factor of the representative's system,
  // analysed here for its size, made at the first step and again when due. With one CG
  // work-group per sigma point only (its finishing shaders); on a CPU device more are made
  // only when a test forces them, and then Jacobi unless the factor is asked for.
  if (vulkan_uses_factor(options.preconditioner, info.type)) {
    const bool asked = options.preconditioner == Preconditioner::factorised;
    if (asked && info.type != "cpu")
      throw DeviceError("--preconditioner factorised: Vulkan has it on a CPU device only (its "
                        "GPU shaders precondition CG with the multigrid V-cycle or Jacobi); device " + info.name);
    if (asked && cg_partitions_ > 1)
      throw DeviceError("--preconditioner factorised: Vulkan has it with one CG work-group per "
                        "sigma point only (" + std::to_string(cg_partitions_) + " asked)");
    if (cg_partitions_ == 1) {
      springs_ = spring_correction(options.spring_correction);   // as OpenCL's
      factor_ = analysed_factor(springs_);   // their rows last, as OpenCL's
      check_device_memory_with_factor(factor_->nonzeros(), FactorStorage::blocks);
      preconditioner_making_.set_rule(options.background_making_steps, options.background_making_solves);
    }
  }
  cg_lane_rows_ = sigmafem::cg_lane_rows(options.cg_sigma_lanes_from, S_, info, !cg_partitioned_, factor_ != nullptr);
  // The partitions' shaders with sigma points side by side: G / lanes rows at once of each.
  if (cg_partitioned_ && groups.sigma_lanes > 1) cg_lane_rows_ = static_cast<int>(cg_group_) / groups.sigma_lanes;
  // Within llvmpipe's loop turns (cg_loop_turns): lanes over sigma points give way to a group a
  // sigma point (or a partition), which grows until its lanes' share of the nodes fits (128
  // invocations a group, Vulkan's least maximum, at most).
  const std::vector<long long> node_turns = cg_node_turns(model_);   // once: the doublings reuse it
  if (cg_lane_rows_ > 0 && cg_loop_turns(node_turns, cg_lane_rows_, cg_partitions_) > options.cg_loop_turns)
    cg_lane_rows_ = 0;
  auto group_turns = [&] { return cg_loop_turns(node_turns, static_cast<int>(cg_group_), cg_partitions_); };
  while (cg_lane_rows_ == 0 && group_turns() > options.cg_loop_turns) {
    if (cg_group_ >= 128)
      throw DeviceError("the mesh's " + std::to_string(nodes_) + " nodes are too many for Vulkan's CG with " +
                        std::to_string(cg_partitions_) + " work-group(s) of 128 a sigma point on " + info.name +
                        " (its loops would turn " + std::to_string(group_turns()) + " times; at most " +
                        std::to_string(options.cg_loop_turns) + ")");
    cg_group_ *= 2;
  }

  // The partitions' buffers are bound but unused with one partition; Jacobi's diagonals and z
  // with the factor (its *_factor shaders and its solve leave them out).
  DeviceBufferSizes sizes{0, cg_partitions_};
  sizes.frame_numbers = frame_numbers();
  sizes.jacobi_diagonals = factor_ == nullptr;
  sizes.cg_z = factor_ == nullptr;
  std::size_t largest = 0;
  for (const DeviceBufferSpec& spec : buffer_specs(sizes)) {
    const std::size_t bytes = take_device_bytes(spec, device_.real_size());
    largest = std::max(largest, bytes);
    buffers_.push_back(device_.buffer(bytes, spec.what));
    if (spec.integer) device_.upload(buffers_.back(), spec.integers.data(), bytes);
    if (!spec.reals.empty()) write_reals(spec.id, spec.reals);
  }
  // Read-back area: 3 flags and 2 scalars per sigma point, then the observations.
  const std::size_t observation_rows = std::max<std::size_t>(1, observed_.size()) * 3;
  device_.reserve_read_back(3 * 4 * static_cast<std::size_t>(S_) +
                            (2 + observation_rows) * S_ * device_.real_size());

  device_.set_texel_reads(vulkan_texel_reads(options.kernel_form, info.type, largest,
                                             info.max_texel_elements));

  using B = DeviceBuffer;
  auto kernel = [&](const char* name, DeviceKernel k, const std::vector<std::uint32_t>& constants = {}) {
    return device_.kernel(name, static_cast<int>(kernel_buffers(k).size()), constants);
  };
  // The element and node shaders four sigma points a lane on a CPU device
  // (kernels/vulkan/sigma_quads.h), where S allows.
  sigma_quads_ = options.sigma_quads && device_.texel_reads() && S_ % 4 == 0;
  // With a factor, the right-hand side's shaders leave out the Jacobi diagonal (*_factor).
  const std::string rhs_form = std::string(sigma_quads_ ? "_quads" : "") + (factor_ ? "_factor" : "");
  // The rotation method as element_rhs's specialization constant 0 (a branch llvmpipe would run
  // both sides of, read from the step constants).
  k_element_rhs_ = kernel(("element_rhs" + rhs_form).c_str(), DeviceKernel::element_rhs,
                          {model_.material.rotation == ElementRotation::polar ? 1u : 0u});
  k_node_rhs_ = kernel(("node_rhs" + rhs_form).c_str(), DeviceKernel::node_rhs);
  k_element_product_ =
      kernel(sigma_quads_ ? "element_product_quads" : "element_product", DeviceKernel::element_product);
  k_node_product_ = kernel(sigma_quads_ ? "node_product_quads" : "node_product", DeviceKernel::node_product);
  k_state_update_ = kernel(sigma_quads_ ? "state_update_quads" : "state_update", DeviceKernel::state_update);
  k_observation_gather_ = kernel("observation_gather", DeviceKernel::observation_gather);
  // The CG shaders (conjugate_gradient.comp): the start's three share one set of bindings
  // (the node rows' buffers first: cg_start does the warm start's gather), the iteration's
  // four another.
  const std::vector<DeviceBuffer>& start = kernel_buffers(DeviceKernel::vulkan_cg_start);
  const std::vector<DeviceBuffer>& iteration = kernel_buffers(DeviceKernel::vulkan_cg_iteration);
  const std::uint32_t partitions = static_cast<std::uint32_t>(cg_partitions_);
  auto cg_kernel = [&](const char* name, const std::vector<DeviceBuffer>& buffers) {
    return device_.kernel(name, static_cast<int>(buffers.size()),
                          {cg_group_, partitions, static_cast<std::uint32_t>(cg_lane_rows_)});
  };
  // Lanes over sigma points two or more a sigma point add their parts by subgroup shuffles: the
  // factor's CG shaders compiled for them.
  auto lanes = [&](const char* name) { return cg_lane_rows_ > 1 ? std::string(name) + "_lanes" : std::string(name); };
  if (!cg_partitioned_) k_cg_start_ = cg_kernel(lanes(factor_ ? "cg_start_factor" : "cg_start").c_str(), start);
  // One partition on a small mesh: two dispatches an iteration (cg_node_iteration forms q = A d
  // itself), where lavapipe's cost per dispatch outweighs their work; on a larger one the
  // three, where node_product's lanes (a node's sigma points) gather faster than
  // cg_node_iteration's (a sigma point's nodes) (bench/RESULTS.md, stop 52).
  node_iteration_ = !cg_partitioned_ &&
                    static_cast<long long>(elements_) * S_ <= options.node_iteration_work;
  // With a factor, the iteration shaders stop at the stop test, and factor_solve follows them,
  // finishing the iteration (r.z and the direction) itself.
  if (node_iteration_)
    k_cg_node_iteration_ = cg_kernel(factor_ ? lanes("cg_node_iteration_factor").c_str() : "cg_node_iteration", iteration);
  else if (!cg_partitioned_)
    k_cg_iteration_ = cg_kernel(factor_ ? lanes("cg_iteration_factor").c_str() : "cg_iteration", iteration);
  if (factor_) {
    // Without z: the solves always finish CG's step (d and r.z), and no shader reads z then.
    const VulkanFactorSolve::CgBuffers cg{buffer(B::r), VulkanBuffer{}, buffer(B::d), buffer(B::active), buffer(B::rz)};
    factor_solve_ = std::make_unique<VulkanFactorSolve>(device_, 3 * nodes_, springs_.size(), S_, cg,
                                                        options.factor_loop_turns);
    device_bytes_ += factor_solve_->bytes();
  }
  if (multigrid_) {
    k_cg_preconditioned_ = cg_kernel("cg_preconditioned", iteration);
    multigrid_solve_ = std::make_unique<VulkanMultigrid>(device_, S_, buffer(B::r), buffer(B::z));
  }
  if (cg_partitioned_) {
    k_cg_start_partials_ = cg_kernel("cg_start_partials", start);
    k_cg_start_scalars_ = cg_kernel("cg_start_scalars", start);
    k_cg_dot_ = cg_kernel("cg_dot", iteration);
    k_cg_update_ = cg_kernel("cg_update", iteration);
    k_cg_direction_ = cg_kernel("cg_direction", iteration);
  }

  s_element_rhs_ = bind(k_element_rhs_, kernel_buffers(DeviceKernel::element_rhs));
  s_node_rhs_ = bind(k_node_rhs_, kernel_buffers(DeviceKernel::node_rhs));
  const std::vector<DeviceBuffer>& product = kernel_buffers(DeviceKernel::element_product);
  s_product_warm_start_ = bind(k_element_product_, with_buffer(with_buffer(product, B::d, B::dv),
                                                               B::active, B::all_active));
  s_product_cg_ = bind(k_element_product_, product);
  s_product_all_ = bind(k_element_product_, with_buffer(product, B::active, B::all_active));
  s_node_product_ = bind(k_node_product_, kernel_buffers(DeviceKernel::node_product));
  if (!cg_partitioned_) s_cg_start_ = bind(k_cg_start_, start);
  if (node_iteration_)
    s_cg_node_iteration_ = bind(k_cg_node_iteration_, iteration);
  else if (!cg_partitioned_)
    s_cg_iteration_ = bind(k_cg_iteration_, iteration);
  if (multigrid_) s_cg_preconditioned_ = bind(k_cg_preconditioned_, iteration);
  if (cg_partitioned_) {
    s_cg_start_partials_ = bind(k_cg_start_partials_, start);
    s_cg_start_scalars_ = bind(k_cg_start_scalars_, start);
    s_cg_dot_ = bind(k_cg_dot_, iteration);
    s_cg_update_ = bind(k_cg_update_, iteration);
    s_cg_direction_ = bind(k_cg_direction_, iteration);
  }
  s_state_update_ = bind(k_state_update_, kernel_buffers(DeviceKernel::state_update));
  s_observation_gather_ = bind(k_observation_gather_, kernel_buffers(DeviceKernel::observation_gather));
  make_recenter(static_cast<std::uint32_t>(parameter_count()));
}

void VulkanEnsemble::make_recenter(std::uint32_t p) {
  const std::vector<DeviceBuffer>& buffers = kernel_buffers(DeviceKernel::recenter);
  k_recenter_ = device_.kernel("recenter", static_cast<int>(buffers.size()), {static_cast<std::uint32_t>(S_), p});
  s_recenter_ = bind(k_recenter_, buffers);
  recenter_parameters_ = p;
}

VkDescriptorSet VulkanEnsemble::bind(const VulkanKernel& kernel, const std::vector<DeviceBuffer>& buffers) {
  std::vector<VulkanBuffer> bound;
  for (DeviceBuffer id : buffers) bound.push_back(buffer(id));
  return device_.bind(kernel, bound);
}

void VulkanEnsemble::write_reals(DeviceBuffer id, const std::vector<double>& values) {
  device_.upload_reals(buffer(id), values);
}

std::vector<double> VulkanEnsemble::read_reals(DeviceBuffer id, std::size_t count) const {
  flush_pending();
  std::vector<unsigned char> bytes(count * device_.real_size());
  device_.download(buffer(id), bytes.data(), bytes.size());
  return from_device_reals(bytes.data(), count, device_.precision());
}

void VulkanEnsemble::upload_ligament_k() {
  pending_ligament_k_ = to_device_reals(ligament_k_, device_.precision());
  coupling_stale_ = springs_.prepared();   // the springs' corrections follow the stiffnesses
  shift_stale_ = multigrid_solve_ && multigrid_solve_->ready();
}

bool VulkanEnsemble::has_pending() const {
  return !pending_ligament_k_.empty() || pending_recenter_;
}

void VulkanEnsemble::record_pending(VkCommandBuffer cmd) const {
  if (!has_pending()) return;
  if (!pending_ligament_k_.empty())
    device_.update(cmd, buffer(DeviceBuffer::ligament_k), pending_ligament_k_.data(), pending_ligament_k_.size());
  if (pending_recenter_) {
    device_.update(cmd, buffer(DeviceBuffer::recenter_scalars), pending_scalars_.data(), pending_scalars_.size());
    device_.update(cmd, buffer(DeviceBuffer::directions), pending_directions_.data(), pending_directions_.size());
    device_.update(cmd, buffer(DeviceBuffer::weights), pending_weights_.data(), pending_weights_.size());
  }
  device_.barrier(cmd);
  if (pending_recenter_)
    dispatch_items(cmd, k_recenter_, s_recenter_, 3 * static_cast<std::size_t>(nodes_),
                   static_cast<std::uint32_t>(3 * nodes_));
  pending_ligament_k_.clear();
  pending_recenter_ = false;
}

void VulkanEnsemble::flush_pending() const {
  if (!has_pending()) return;
  VkCommandBuffer cmd = device_.begin();
  record_pending(cmd);
  device_.submit_and_wait(cmd);
}

void VulkanEnsemble::dispatch_items(VkCommandBuffer cmd, const VulkanKernel& kernel,
                                    VkDescriptorSet set, std::size_t items,
                                    std::uint32_t count) const {
  PushConstants push;
  push.S = static_cast<std::uint32_t>(S_);
  push.count = count;
  push.max_iterations = model_.solver.cg_max_iterations;
  push.p = recenter_parameters_;
  device_.dispatch(cmd, kernel, set, &push, groups_for(items));
  device_.barrier(cmd);
}

std::size_t VulkanEnsemble::element_items() const {
  return elements_ * static_cast<std::size_t>(sigma_quads_ ? S_ / 4 : S_);
}

std::size_t VulkanEnsemble::node_items() const {
  return nodes_ * static_cast<std::size_t>(sigma_quads_ ? S_ / 4 : S_);
}

std::uint32_t VulkanEnsemble::cg_groups() const {
  const std::uint32_t S = static_cast<std::uint32_t>(S_);
  const std::uint32_t J = static_cast<std::uint32_t>(cg_lane_rows_);
  return (J > 0 ? (J * S + cg_group_ - 1) / cg_group_ : S) * static_cast<std::uint32_t>(cg_partitions_);
}

void VulkanEnsemble::record_system_product(VkCommandBuffer cmd, VkDescriptorSet product_set) const {
  dispatch_items(cmd, k_element_product_, product_set, element_items(), elements_);
  dispatch_items(cmd, k_node_product_, s_node_product_, node_items(), nodes_);
}

void VulkanEnsemble::record_cg_iterations(VkCommandBuffer cmd, int count) const {
  PushConstants push;
  push.S = static_cast<std::uint32_t>(S_);
  push.count = static_cast<std::uint32_t>(nodes_);
  push.max_iterations = model_.solver.cg_max_iterations;
  const std::uint32_t groups = cg_groups();
  for (int i = 0; i < count; ++i) {
    if (node_iteration_) {
      dispatch_items(cmd, k_element_product_, s_product_cg_, element_items(), elements_);
      device_.dispatch(cmd, k_cg_node_iteration_, s_cg_node_iteration_, &push, groups);
    } else if (cg_partitioned_) {
      record_system_product(cmd, s_product_cg_);
      device_.dispatch(cmd, k_cg_dot_, s_cg_dot_, &push, groups);
      device_.barrier(cmd);
      device_.dispatch(cmd, k_cg_update_, s_cg_update_, &push, groups);
      device_.barrier(cmd);
      record_multigrid(cmd, false);
      device_.dispatch(cmd, k_cg_direction_, s_cg_direction_, &push, groups);
    } else {
      record_system_product(cmd, s_product_cg_);
      device_.dispatch(cmd, k_cg_iteration_, s_cg_iteration_, &push, groups);
    }
    device_.barrier(cmd);
    if (factor_) factor_solve_->record(cmd, SF_FACTOR_FINISH_DIRECTION);
  }
}

void VulkanEnsemble::record_multigrid(VkCommandBuffer cmd, bool start) const {
  // Until a hierarchy has gone down, the Jacobi z of cg_start_partials and cg_update.
  if (!multigrid_solve_ || !multigrid_solve_->ready()) return;
  multigrid_solve_->record(cmd);
  PushConstants push;
  push.S = static_cast<std::uint32_t>(S_);
  push.count = static_cast<std::uint32_t>(nodes_);
  push.max_iterations = model_.solver.cg_max_iterations;
  push.p = start ? 1u : 0u;
  device_.dispatch(cmd, k_cg_preconditioned_, s_cg_preconditioned_, &push, cg_groups());
  device_.barrier(cmd);
}

void VulkanEnsemble::refresh_multigrid(const std::vector<double>& constants) {
  // In the background where the device has a hierarchy to step on meanwhile (as
  // OpenClEnsemble's): a failed making leaves that one in place.
  if (multigrid_makings_ > 0 && preconditioner_making_.takes(multigrid_->setup_in_cycles())) {
    making_springs_ = factorised_springs(shift_rows_, constants);
    preconditioner_making_.start([this, system = representative_system_later()] { return multigrid_->set_matrix(system()); });
    return;
  }
  const bool made = multigrid_->set_matrix(representative_system());
  multigrid_refresh_.made(made, multigrid_->setup_in_cycles());
  // Else the last hierarchy stays, or Jacobi until one is made.
  if (made) upload_multigrid(factorised_springs(shift_rows_, constants));
}

void VulkanEnsemble::upload_multigrid(const std::vector<double>& springs) {
  const std::size_t before = multigrid_solve_->bytes();   // its buffers are made at the first upload
  if (!multigrid_solve_->ready())
    check_more_device_memory(multigrid_memory(*multigrid_, S_, device_.real_size()), "the multigrid levels");
  multigrid_solve_->upload(*multigrid_);
  device_bytes_ += multigrid_solve_->bytes() - before;
  ++multigrid_makings_;
  multigrid_springs_ = springs;
  shift_stale_ = true;
}

void VulkanEnsemble::hand_over_making(bool made) {
  if (factor_) {
    if (made) upload_factor(making_springs_);
    return;
  }
  multigrid_refresh_.made(made, multigrid_->setup_in_cycles());
  if (made) upload_multigrid(making_springs_);
}

void VulkanEnsemble::refresh_factor(const std::vector<double>& constants) {
  // A large factor in the background where the device has one to step on meanwhile (as
  // OpenClEnsemble's): a failed making leaves that one in place.
  if (factor_makings_ > 0 && preconditioner_making_.takes(factor_->factorisation_in_solves())) {
    making_springs_ = factorised_springs(springs_, constants);
    preconditioner_making_.start([this, system = representative_system_later()] { return factor_->factorise(system()); });
    return;
  }
  // A matrix that is not positive definite (a diverged state?) leaves the last factor in
  // place, and the next step tries again.
  const Eigen::SparseMatrix<double> A = representative_system();
  if (!factor_->factorise(A)) {
    if (!factor_solve_->ready()) {
      const std::size_t before = factor_solve_->bytes();
      factor_solve_->upload_diagonal(A);
      device_bytes_ += factor_solve_->bytes() - before;
    }
    return;
  }
  upload_factor(factorised_springs(springs_, constants));
}

void VulkanEnsemble::upload_factor(const std::vector<double>& springs) {
  const std::size_t before = factor_solve_->bytes();   // a new pattern's buffers are made at its upload
  ++factor_makings_;
  factor_solve_->upload(*factor_);
  device_bytes_ += factor_solve_->bytes() - before;
  if (springs_.size() == 0) return;
  springs_.prepare(*factor_);
  if (!factor_solve_->upload_springs(springs_)) {
    springs_ = SpringCorrection();   // too large a correction for a dispatch: the factor alone
    return;
  }
  factorised_springs_ = springs;
  coupling_stale_ = true;
}

StepReport VulkanEnsemble::advance(const Eigen::Vector3d& so_position) {
  const std::size_t S = static_cast<std::size_t>(S_);
  const std::size_t real = device_.real_size();
  // Read-back offsets: active, iterations, converged (uint32), rr, bb, observations (reals).
  const std::size_t at_active = 0, at_iterations = 4 * S, at_converged = 8 * S;
  const std::size_t at_rr = 12 * S, at_bb = at_rr + real * S, at_observations = at_bb + real * S;
  last_step_waits_ = 0;
  observations_current_ = false;
  const int factorisations_before = factorisations();
  const std::vector<double> step_constants = step_constants_.next_step(model_, so_position);
  if (preconditioner_making_.pending()) {
    bool made = false;
    if (preconditioner_making_.hand_over(made)) hand_over_making(made);
  } else if (factor_ && factor_->due()) {
    refresh_factor(step_constants);
  } else if (multigrid_ && multigrid_refresh_.due()) {
    refresh_multigrid(step_constants);
  }

  // The right-hand side, the warm start and the first batch of iterations: as many as the
  // last step needed (warm-started steps need about the same).
  VkCommandBuffer cmd = device_.begin();
  record_pending(cmd);
  const std::vector<unsigned char> constants = to_device_reals(step_constants, device_.precision());
  device_.update(cmd, buffer(DeviceBuffer::constants), constants.data(), constants.size());
  if (coupling_stale_) {   // the springs' couplings for this step's stiffnesses (or factor)
    factor_solve_->record_couplings(cmd, spring_couplings(springs_, step_constants, factorised_springs_));
    coupling_stale_ = false;
  }
  if (shift_stale_) {   // the sigma points' springs against the multigrid hierarchy's
    multigrid_solve_->record_shift(cmd, spring_shift_rows(shift_rows_, step_constants, multigrid_springs_));
    shift_stale_ = false;
  }
  device_.barrier(cmd);
  dispatch_items(cmd, k_element_rhs_, s_element_rhs_, element_items(), elements_);
  dispatch_items(cmd, k_node_rhs_, s_node_rhs_, node_items(), nodes_);
  // The warm start's products K_e dv_e; cg_start gathers them itself.
  dispatch_items(cmd, k_element_product_, s_product_warm_start_, element_items(), elements_);
  PushConstants push;
  push.S = static_cast<std::uint32_t>(S_);
  push.count = static_cast<std::uint32_t>(nodes_);
  if (cg_partitioned_) {
    device_.dispatch(cmd, k_cg_start_partials_, s_cg_start_partials_, &push, cg_groups());
    device_.barrier(cmd);
    record_multigrid(cmd, true);
    device_.dispatch(cmd, k_cg_start_scalars_, s_cg_start_scalars_, &push,
                     (static_cast<std::uint32_t>(S_) + cg_group_ - 1) / cg_group_);
  } else {
    device_.dispatch(cmd, k_cg_start_, s_cg_start_, &push, cg_groups());
  }
  device_.barrier(cmd);
  if (factor_) factor_solve_->record(cmd, SF_FACTOR_FINISH_START);

  // Then batches until every sigma point is done or the cap is reached, each submitted and
  // waited for, with the S active flags read back.
  std::vector<std::uint32_t> active(S);
  iterate_in_batches([&](int count) {
    record_cg_iterations(cmd, count);
    device_.copy_to_host(cmd, buffer(DeviceBuffer::active), 4 * S, at_active);
    device_.submit_and_wait(cmd);
    ++last_step_waits_;
    std::memcpy(active.data(), static_cast<const unsigned char*>(device_.read_back()) + at_active,
                4 * S);
    cmd = device_.begin();
    return std::any_of(active.begin(), active.end(), [](std::uint32_t a) { return a != 0; });
  });

  // The state update, the solver report and the observations, in one more submission.
  dispatch_items(cmd, k_state_update_, s_state_update_, 3 * node_items(),
                 static_cast<std::uint32_t>(3 * nodes_));
  const std::size_t rows = 3 * observed_.size();
  if (rows > 0) {
    dispatch_items(cmd, k_observation_gather_, s_observation_gather_, rows * S,
                   static_cast<std::uint32_t>(observed_.size()));
    device_.copy_to_host(cmd, buffer(DeviceBuffer::observations), rows * S * real, at_observations);
  }
  device_.copy_to_host(cmd, buffer(DeviceBuffer::iterations), 4 * S, at_iterations);
  device_.copy_to_host(cmd, buffer(DeviceBuffer::converged), 4 * S, at_converged);
  device_.copy_to_host(cmd, buffer(DeviceBuffer::rr), real * S, at_rr);
  device_.copy_to_host(cmd, buffer(DeviceBuffer::bb), real * S, at_bb);
  device_.submit_and_wait(cmd);
  ++last_step_waits_;

  const unsigned char* area = static_cast<const unsigned char*>(device_.read_back());
  std::vector<std::int32_t> iterations(S);
  std::vector<std::uint32_t> converged(S);
  std::memcpy(iterations.data(), area + at_iterations, 4 * S);
  std::memcpy(converged.data(), area + at_converged, 4 * S);
  const Precision precision = device_.precision();
  if (rows > 0) {
    observations_cache_ = from_device_reals(area + at_observations, rows * S, precision);
    observations_current_ = true;
  }
  StepReport report = step_report(iterations, converged, from_device_reals(area + at_rr, S, precision),
                                  from_device_reals(area + at_bb, S, precision));
  // Not while a preconditioner is being made (the rule counts from the step it is handed over).
  if (!preconditioner_making_.pending()) {
    const int most = *std::max_element(iterations.begin(), iterations.end());
    if (factor_) factor_->record(most);
    if (multigrid_) multigrid_refresh_.record(most);
  }
  report.factorisations = factorisations() - factorisations_before;
  return report;
}

void VulkanEnsemble::predicted_observations(Eigen::MatrixXd& y) const {
  const std::size_t rows = observed_.size() * 3;
  if (rows == 0) {
    y.resize(0, S_);
    return;
  }
  if (!observations_current_) {
    VkCommandBuffer cmd = device_.begin();
    record_pending(cmd);
    dispatch_items(cmd, k_observation_gather_, s_observation_gather_, rows * S_,
                   static_cast<std::uint32_t>(observed_.size()));
    device_.copy_to_host(cmd, buffer(DeviceBuffer::observations), rows * S_ * device_.real_size(), 0);
    device_.submit_and_wait(cmd);
    observations_cache_ = from_device_reals(device_.read_back(), rows * S_, device_.precision());
    observations_current_ = true;
  }
  y = from_sigma_rows(observations_cache_, rows, S_);
}

void VulkanEnsemble::recenter(const Recentering& r) {
  const RecenteringInputs in = pack_recentering(r, S_, "VulkanEnsemble");
  if (in.p != recenter_parameters_) make_recenter(in.p);   // a wrapper's parameters (EffectEnsemble)
  const Precision precision = device_.precision();
  pending_scalars_ = to_device_reals(in.scalars, precision);
  pending_directions_ = to_device_reals(in.directions, precision);
  pending_weights_ = to_device_reals(in.weights, precision);
  pending_recenter_ = true;
  observations_current_ = false;
}

void VulkanEnsemble::run_system_product() {
  VkCommandBuffer cmd = device_.begin();
  record_pending(cmd);
  record_system_product(cmd, s_product_all_);
  device_.submit_and_wait(cmd);
}

}  // namespace sigmafem
