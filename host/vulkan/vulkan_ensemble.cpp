#include "host/vulkan/vulkan_ensemble.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

#include "host/ensemble/device_readout.h"
#include "host/ensemble/ensemble_tables.h"
#include "step_constants.h"

namespace sigmafem {
namespace {

constexpr std::size_t kItemsPerGroup = 64;   // SF_ITEMS_PER_GROUP in kernels/vulkan/ensemble_layout.h

std::uint32_t groups_for(std::size_t items) {
  return static_cast<std::uint32_t>((items + kItemsPerGroup - 1) / kItemsPerGroup);
}

}  // namespace

VulkanEnsemble::VulkanEnsemble(const Model& model, std::vector<int> estimated,
                               ObservedPoints observed, int sigma_count,
                               const DeviceOptions& options)
    : device_(options.device, options.precision),
      model_(model),
      step_constants_(model, sigma_count, device_cg_tolerance(model, options.precision)),
      estimated_(std::move(estimated)),
      observed_(std::move(observed)),
      S_(sigma_count),
      nodes_(model.node_count()),
      elements_(model.element_count()) {
  check_ensemble_arguments(model, estimated_, observed_, S_, "VulkanEnsemble");
  tolerance_ = device_cg_tolerance(model, options.precision);

  // Check the memory before asking for it, to say how much is needed.
  const std::size_t dof = 3 * static_cast<std::size_t>(nodes_) * S_;
  const std::size_t per_element = static_cast<std::size_t>(elements_) * S_;
  const EnsembleMemory need = ensemble_memory(nodes_, elements_, S_, device_.real_size());
  const VulkanDeviceInfo& info = device_.info();
  if (need.largest > info.max_buffer || need.total > info.memory)
    throw DeviceError(out_of_device_memory_message(need, elements_, S_, info.name,
                                                   info.memory, info.max_buffer));
  // CG's work-groups per sigma point (conjugate_gradient.comp): by the mesh on a GPU, one on
  // a CPU (lavapipe), where S groups already keep its few cores busy, unless a test forces it.
  cg_partitions_ = info.type == "cpu" && options.cg_partitions == 0
                       ? 1
                       : cg_partitions(nodes_, options.cg_partitions);
  // The CG shaders take S x partitions work-groups along x.
  if (static_cast<std::uint64_t>(S_) * cg_partitions_ > device_.max_group_count())
    throw DeviceError("Vulkan device " + info.name + " runs at most " +
                      std::to_string(device_.max_group_count() / cg_partitions_) +
                      " sigma points on this mesh");
  EnsembleTables tables = make_ensemble_tables(model, S_);
  ligament_k_ = std::move(tables.ligament_k);
  // Work-items per sigma point in CG: on a CPU (lavapipe) one SIMD register's worth, so that
  // a group's barriers cost nothing; on a GPU 64 (two warps, one wavefront).
  cg_group_ = info.type == "cpu" ? 8 : 64;

  element_nodes_ = make_buffer(tables.element_nodes, "element nodes");
  element_rest_ = make_buffer(tables.element_rest, "element rest state");
  incidence_offsets_ = make_buffer(tables.incidence_offsets, "node incidence");
  incidence_ = make_buffer(tables.incidence, "node incidence");
  ligament_offsets_ = make_buffer(tables.ligament_offsets, "ligament nodes");
  ligament_of_node_ = make_buffer(tables.ligament_of_node, "ligament nodes");
  control_k_ = make_buffer(tables.control_k, "control springs");
  mass_ = make_buffer(tables.mass, "mass");
  rest_positions_ = make_buffer(tables.rest_positions, "rest positions");
  observed_nodes_ = make_buffer(corner_nodes(observed_), "observed points");
  observed_weights_ = make_buffer(corner_weights(observed_), "observed points");
  constants_ = make_buffer(step_constants_.size(), "step constants");
  ligament_k_buffer_ = make_buffer(ligament_k_, "ligament stiffness");
  x_ = make_buffer(tables.initial_positions, "positions");
  const std::vector<double> zeros(dof, 0.0);
  v_ = make_buffer(zeros, "velocities");
  dv_ = make_buffer(zeros, "velocity change");
  for (VulkanBuffer* b : {&rhs_, &inverse_diagonal_, &r_, &z_, &d_, &q_})
    *b = make_buffer(dof, "CG vectors");
  frames_ = make_buffer(9 * per_element, "element frames");
  element_out_ = make_buffer(12 * per_element, "element outputs");
  element_diagonal_ = make_buffer(12 * per_element, "element diagonals");
  const std::size_t observation_rows = std::max<std::size_t>(1, observed_.size()) * 3;
  observations_ = make_buffer(observation_rows * S_, "observations");
  for (VulkanBuffer* b : {&bb_, &rr_, &rz_}) *b = make_buffer(static_cast<std::size_t>(S_), "CG scalars");
  for (VulkanBuffer* b : {&active_, &converged_, &iterations_})
    *b = make_buffer(std::vector<int>(S_, 0), "CG flags");
  all_active_ = make_buffer(std::vector<int>(S_, 1), "CG flags");
  // The partitions' partial sums and each (sigma point, partition) group's own scalars (bound
  // but unused with one partition).
  const std::size_t cg_groups = static_cast<std::size_t>(S_) * cg_partitions_;
  partial_ = make_buffer(4 * cg_groups, "CG partial sums");
  own_rz_ = make_buffer(cg_groups, "CG scalars");
  const std::vector<int> flags(cg_groups, 0);
  own_active_ = make_buffer(flags, "CG flags");
  own_iterations_ = make_buffer(flags, "CG flags");
  recenter_scalars_ = make_buffer(1 + kDeviceMaxParameters, "re-centring");
  directions_ = make_buffer(static_cast<std::size_t>(kDeviceMaxParameters) * S_, "re-centring");
  weights_ = make_buffer(static_cast<std::size_t>(kDeviceMaxParameters) * S_, "re-centring");
  // Read-back area: 3 flags and 2 scalars per sigma point, then the observations.
  device_.reserve_read_back(3 * 4 * static_cast<std::size_t>(S_) +
                            (2 + observation_rows) * S_ * device_.real_size());

  // Bindings in the order of each shader's (and the OpenCL kernel's) buffer arguments.
  k_element_rhs_ = device_.kernel("element_rhs", 8);
  k_node_rhs_ = device_.kernel("node_rhs", 15);
  k_element_product_ = device_.kernel("element_product", 7);
  k_node_product_ = device_.kernel("node_product", 11);
  // The CG shaders: the start's three share 25 bindings, the iteration's four 17.
  const std::uint32_t partitions = static_cast<std::uint32_t>(cg_partitions_);
  k_cg_start_ = device_.kernel("cg_start", 25, cg_group_, partitions);
  k_cg_iteration_ = device_.kernel("cg_iteration", 17, cg_group_, partitions);
  if (cg_partitions_ > 1) {
    k_cg_start_partials_ = device_.kernel("cg_start_partials", 25, cg_group_, partitions);
    k_cg_start_scalars_ = device_.kernel("cg_start_scalars", 25, cg_group_, partitions);
    k_cg_dot_ = device_.kernel("cg_dot", 17, cg_group_, partitions);
    k_cg_update_ = device_.kernel("cg_update", 17, cg_group_, partitions);
    k_cg_direction_ = device_.kernel("cg_direction", 17, cg_group_, partitions);
  }
  k_state_update_ = device_.kernel("state_update", 5);
  k_observation_gather_ = device_.kernel("observation_gather", 4);
  k_recenter_ = device_.kernel("recenter", 5);

  s_element_rhs_ = device_.bind(k_element_rhs_, {element_nodes_, element_rest_, frames_, x_, v_,
                                                 constants_, element_out_, element_diagonal_});
  const std::vector<VulkanBuffer> node_shared = {constants_, incidence_offsets_, incidence_,
                                                 ligament_offsets_, ligament_of_node_,
                                                 ligament_k_buffer_, control_k_, mass_};
  auto with_shared = [&](std::vector<VulkanBuffer> rest) {
    std::vector<VulkanBuffer> all = node_shared;
    all.insert(all.end(), rest.begin(), rest.end());
    return all;
  };
  s_node_rhs_ = device_.bind(k_node_rhs_, with_shared({rest_positions_, x_, v_, element_out_,
                                                       element_diagonal_, rhs_, inverse_diagonal_}));
  s_product_warm_start_ = device_.bind(
      k_element_product_, {element_nodes_, element_rest_, frames_, dv_, all_active_, element_out_, constants_});
  s_product_cg_ = device_.bind(k_element_product_,
                               {element_nodes_, element_rest_, frames_, d_, active_, element_out_, constants_});
  s_product_all_ = device_.bind(
      k_element_product_, {element_nodes_, element_rest_, frames_, d_, all_active_, element_out_, constants_});
  s_node_product_ = device_.bind(k_node_product_, with_shared({d_, element_out_, q_}));
  const std::vector<VulkanBuffer> start_buffers = with_shared(
      {element_out_, rhs_, inverse_diagonal_, dv_, r_, z_, d_, bb_, rr_, rz_, active_, converged_,
       iterations_, partial_, own_active_, own_iterations_, own_rz_});
  const std::vector<VulkanBuffer> iteration_buffers = {
      constants_, inverse_diagonal_, dv_,     r_,          z_,         d_,
      q_,         bb_,               rr_,     rz_,         active_,    converged_,
      iterations_, partial_,         own_active_, own_iterations_, own_rz_};
  s_cg_start_ = device_.bind(k_cg_start_, start_buffers);
  s_cg_iteration_ = device_.bind(k_cg_iteration_, iteration_buffers);
  if (cg_partitions_ > 1) {
    s_cg_start_partials_ = device_.bind(k_cg_start_partials_, start_buffers);
    s_cg_start_scalars_ = device_.bind(k_cg_start_scalars_, start_buffers);
    s_cg_dot_ = device_.bind(k_cg_dot_, iteration_buffers);
    s_cg_update_ = device_.bind(k_cg_update_, iteration_buffers);
    s_cg_direction_ = device_.bind(k_cg_direction_, iteration_buffers);
  }
  s_state_update_ = device_.bind(k_state_update_, {constants_, bb_, dv_, x_, v_});
  s_observation_gather_ =
      device_.bind(k_observation_gather_, {observed_nodes_, observed_weights_, x_, observations_});
  s_recenter_ = device_.bind(k_recenter_, {recenter_scalars_, directions_, weights_, x_, v_});
}

VulkanBuffer VulkanEnsemble::make_buffer(std::size_t count, const char* what) {
  const std::size_t bytes = std::max<std::size_t>(1, count) * device_.real_size();
  device_bytes_ += bytes;
  return device_.buffer(bytes, what);
}

VulkanBuffer VulkanEnsemble::make_buffer(const std::vector<double>& values, const char* what) {
  VulkanBuffer buffer = make_buffer(values.size(), what);
  write(buffer, values);
  return buffer;
}

VulkanBuffer VulkanEnsemble::make_buffer(const std::vector<int>& values, const char* what) {
  const std::size_t bytes = values.size() * sizeof(std::int32_t);
  device_bytes_ += bytes;
  VulkanBuffer buffer = device_.buffer(bytes, what);
  device_.upload(buffer, values.data(), bytes);
  return buffer;
}

void VulkanEnsemble::write(const VulkanBuffer& buffer, const std::vector<double>& values) const {
  const std::vector<unsigned char> bytes = to_device_reals(values, device_.precision());
  device_.upload(buffer, bytes.data(), bytes.size());
}

std::vector<double> VulkanEnsemble::read(const VulkanBuffer& buffer, std::size_t count) const {
  std::vector<unsigned char> bytes(count * device_.real_size());
  device_.download(buffer, bytes.data(), bytes.size());
  return from_device_reals(bytes.data(), count, device_.precision());
}

std::vector<double> VulkanEnsemble::column_of(const VulkanBuffer& buffer, std::size_t rows,
                                              int s) const {
  flush_pending();
  return sigma_column(read(buffer, rows * S_), rows, S_, s, "VulkanEnsemble");
}

void VulkanEnsemble::set_parameters(const Eigen::MatrixXd& theta) {
  check_parameter_matrix(theta, parameter_count(), sigma_count(), "VulkanEnsemble");
  set_ligament_stiffness(model_, estimated_, theta, S_, ligament_k_);
  pending_ligament_k_ = to_device_reals(ligament_k_, device_.precision());
}

bool VulkanEnsemble::has_pending() const {
  return !pending_ligament_k_.empty() || pending_recenter_;
}

void VulkanEnsemble::record_pending(VkCommandBuffer cmd) const {
  if (!has_pending()) return;
  if (!pending_ligament_k_.empty())
    device_.update(cmd, ligament_k_buffer_, pending_ligament_k_.data(), pending_ligament_k_.size());
  if (pending_recenter_) {
    device_.update(cmd, recenter_scalars_, pending_scalars_.data(), pending_scalars_.size());
    device_.update(cmd, directions_, pending_directions_.data(), pending_directions_.size());
    device_.update(cmd, weights_, pending_weights_.data(), pending_weights_.size());
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

void VulkanEnsemble::record_system_product(VkCommandBuffer cmd, VkDescriptorSet product_set) const {
  const std::size_t S = static_cast<std::size_t>(S_);
  dispatch_items(cmd, k_element_product_, product_set, elements_ * S, elements_);
  dispatch_items(cmd, k_node_product_, s_node_product_, nodes_ * S, nodes_);
}

void VulkanEnsemble::record_cg_iterations(VkCommandBuffer cmd, int count) const {
  PushConstants push;
  push.S = static_cast<std::uint32_t>(S_);
  push.count = static_cast<std::uint32_t>(nodes_);
  push.max_iterations = model_.solver.cg_max_iterations;
  const std::uint32_t groups = static_cast<std::uint32_t>(S_ * cg_partitions_);
  for (int i = 0; i < count; ++i) {
    record_system_product(cmd, s_product_cg_);
    if (cg_partitions_ > 1) {
      device_.dispatch(cmd, k_cg_dot_, s_cg_dot_, &push, groups);
      device_.barrier(cmd);
      device_.dispatch(cmd, k_cg_update_, s_cg_update_, &push, groups);
      device_.barrier(cmd);
      device_.dispatch(cmd, k_cg_direction_, s_cg_direction_, &push, groups);
    } else {
      device_.dispatch(cmd, k_cg_iteration_, s_cg_iteration_, &push, groups);
    }
    device_.barrier(cmd);
  }
}

StepReport VulkanEnsemble::advance(const Eigen::Vector3d& so_position) {
  const std::size_t S = static_cast<std::size_t>(S_);
  const std::size_t real = device_.real_size();
  // Read-back offsets: active, iterations, converged (uint32), rr, bb, observations (reals).
  const std::size_t at_active = 0, at_iterations = 4 * S, at_converged = 8 * S;
  const std::size_t at_rr = 12 * S, at_bb = at_rr + real * S, at_observations = at_bb + real * S;
  last_step_waits_ = 0;
  observations_current_ = false;

  // The right-hand side, the warm start and the first batch of iterations: as many as the
  // last step needed (warm-started steps need about the same).
  VkCommandBuffer cmd = device_.begin();
  record_pending(cmd);
  const std::vector<unsigned char> constants =
      to_device_reals(step_constants_.next_step(model_, so_position), device_.precision());
  device_.update(cmd, constants_, constants.data(), constants.size());
  device_.barrier(cmd);
  dispatch_items(cmd, k_element_rhs_, s_element_rhs_, elements_ * S, elements_);
  dispatch_items(cmd, k_node_rhs_, s_node_rhs_, nodes_ * S, nodes_);
  // The warm start's products K_e dv_e; cg_start gathers them itself.
  dispatch_items(cmd, k_element_product_, s_product_warm_start_, elements_ * S, elements_);
  PushConstants push;
  push.S = static_cast<std::uint32_t>(S_);
  push.count = static_cast<std::uint32_t>(nodes_);
  if (cg_partitions_ > 1) {
    device_.dispatch(cmd, k_cg_start_partials_, s_cg_start_partials_, &push,
                     static_cast<std::uint32_t>(S_ * cg_partitions_));
    device_.barrier(cmd);
    device_.dispatch(cmd, k_cg_start_scalars_, s_cg_start_scalars_, &push,
                     (static_cast<std::uint32_t>(S_) + cg_group_ - 1) / cg_group_);
  } else {
    device_.dispatch(cmd, k_cg_start_, s_cg_start_, &push, static_cast<std::uint32_t>(S_));
  }
  device_.barrier(cmd);

  // Then batches until every sigma point is done or the cap is reached. A sigma point that
  // is done is left alone by the shaders, so iterations past its end change nothing.
  const int cap = model_.solver.cg_max_iterations;
  int batch = std::max(1, expected_iterations_);
  std::vector<std::uint32_t> active(S);
  for (int done = 0; done < cap;) {
    const int count = std::min(batch, cap - done);
    record_cg_iterations(cmd, count);
    done += count;
    device_.copy_to_host(cmd, active_, 4 * S, at_active);
    device_.submit_and_wait(cmd);
    ++last_step_waits_;
    std::memcpy(active.data(), static_cast<const unsigned char*>(device_.read_back()) + at_active,
                4 * S);
    cmd = device_.begin();
    if (std::none_of(active.begin(), active.end(), [](std::uint32_t a) { return a != 0; })) break;
    batch = std::max(2, expected_iterations_ / 8);
  }

  // The state update, the solver report and the observations, in one more submission.
  dispatch_items(cmd, k_state_update_, s_state_update_, 3 * nodes_ * S,
                 static_cast<std::uint32_t>(3 * nodes_));
  const std::size_t rows = 3 * observed_.size();
  if (rows > 0) {
    dispatch_items(cmd, k_observation_gather_, s_observation_gather_, rows * S,
                   static_cast<std::uint32_t>(observed_.size()));
    device_.copy_to_host(cmd, observations_, rows * S * real, at_observations);
  }
  device_.copy_to_host(cmd, iterations_, 4 * S, at_iterations);
  device_.copy_to_host(cmd, converged_, 4 * S, at_converged);
  device_.copy_to_host(cmd, rr_, real * S, at_rr);
  device_.copy_to_host(cmd, bb_, real * S, at_bb);
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
  expected_iterations_ = *std::max_element(iterations.begin(), iterations.end());
  return solver_report(iterations, converged, from_device_reals(area + at_rr, S, precision),
                       from_device_reals(area + at_bb, S, precision));
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
    device_.copy_to_host(cmd, observations_, rows * S_ * device_.real_size(), 0);
    device_.submit_and_wait(cmd);
    observations_cache_ = from_device_reals(device_.read_back(), rows * S_, device_.precision());
    observations_current_ = true;
  }
  y = from_sigma_rows(observations_cache_, rows, S_);
}

void VulkanEnsemble::set_physics_effects(const std::vector<PhysicsEffects>& effects) {
  step_constants_.set_physics_effects(effects, "VulkanEnsemble");
}

void VulkanEnsemble::recenter(const Recentering& r) {
  const RecenteringInputs in = pack_recentering(r, S_, "VulkanEnsemble");
  recenter_parameters_ = in.p;
  const Precision precision = device_.precision();
  pending_scalars_ = to_device_reals(in.scalars, precision);
  pending_directions_ = to_device_reals(in.directions, precision);
  pending_weights_ = to_device_reals(in.weights, precision);
  pending_recenter_ = true;
  observations_current_ = false;
}

Eigen::VectorXd VulkanEnsemble::positions(int s) const {
  const std::vector<double> column = column_of(x_, 3 * static_cast<std::size_t>(nodes_), s);
  return Eigen::Map<const Eigen::VectorXd>(column.data(), static_cast<Eigen::Index>(column.size()));
}

Eigen::VectorXd VulkanEnsemble::velocities(int s) const {
  const std::vector<double> column = column_of(v_, 3 * static_cast<std::size_t>(nodes_), s);
  return Eigen::Map<const Eigen::VectorXd>(column.data(), static_cast<Eigen::Index>(column.size()));
}

std::vector<double> VulkanEnsemble::frames(int s) const {
  return column_of(frames_, 9 * static_cast<std::size_t>(elements_), s);
}

Eigen::MatrixXd VulkanEnsemble::system_product(const Eigen::MatrixXd& d) {
  const std::size_t rows = 3 * static_cast<std::size_t>(nodes_);
  if (static_cast<std::size_t>(d.rows()) != rows || d.cols() != S_)
    throw std::invalid_argument("VulkanEnsemble::system_product: expected 3N x S");
  write(d_, to_sigma_rows(d));
  VkCommandBuffer cmd = device_.begin();
  record_pending(cmd);
  record_system_product(cmd, s_product_all_);
  device_.submit_and_wait(cmd);
  return from_sigma_rows(read(q_, rows * S_), rows, S_);
}

std::string VulkanEnsemble::description() const {
  return device_ensemble_description("vulkan", device_.precision(), device_.info().name);
}

}  // namespace sigmafem
