#include "host/opencl/opencl_ensemble.h"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "host/ensemble/device_readout.h"
#include "host/ensemble/ensemble_tables.h"
#include "step_constants.h"

namespace sigmafem {
namespace {

constexpr std::size_t kGroup = 64;        // work-group size of the element and node kernels

std::size_t round_up(std::size_t n, std::size_t multiple) {
  return (n + multiple - 1) / multiple * multiple;
}

// Sets the kernel's arguments in order.
template <class... Args>
void set_args(cl::Kernel& kernel, const Args&... args) {
  cl_uint index = 0;
  (kernel.setArg(index++, args), ...);
}

}  // namespace

OpenClEnsemble::OpenClEnsemble(const Model& model, std::vector<int> estimated,
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
  check_ensemble_arguments(model, estimated_, observed_, S_, "OpenClEnsemble");
  tolerance_ = device_cg_tolerance(model, options.precision);

  // Check the memory before asking for it, to say how much is needed.
  const std::size_t dof = 3 * static_cast<std::size_t>(nodes_) * S_;
  const std::size_t per_element = static_cast<std::size_t>(elements_) * S_;
  const EnsembleMemory need = ensemble_memory(nodes_, elements_, S_, device_.real_size());
  const OpenClDeviceInfo& info = device_.info();
  if (need.largest > info.max_allocation || need.total > info.global_memory)
    throw DeviceError(out_of_device_memory_message(need, elements_, S_, info.name,
                                                   info.global_memory, info.max_allocation));
  EnsembleTables tables = make_ensemble_tables(model, S_);
  ligament_k_ = std::move(tables.ligament_k);

  // The CPU form or the GPU form of the kernels (DeviceOptions::kernel_form): the device's
  // type decides unless a test forces one.
  const bool cpu_form = options.kernel_form == KernelForm::automatic ? info.type == "cpu"
                                                                     : options.kernel_form == KernelForm::cpu;
  // Element kernels: on a CPU device one work-item takes an element for all S sigma points,
  // so the compiler vectorises over them; elsewhere one work-item per (element, sigma).
  sigma_block_ = cpu_form ? S_ : 1;
  // On a CPU the element product goes in contiguous chunks of elements, one per compute unit,
  // each adding into its own copy of K d (element_product.cl), instead of element outputs.
  element_chunks_ = cpu_form ? static_cast<int>(std::max(1u, info.compute_units)) : 0;
  // The CG kernels (conjugate_gradient.cl): on a GPU a work-group of 64 per sigma point; on
  // a CPU a work-item per block of sigma points, the blocks shared out over the compute
  // units (and dividing S, so that the kernels' loops over a block have a fixed length).
  cg_per_group_ = !cpu_form;
  // The whole solve in one launch (cg_solve, CPU only) where an iteration's work is small
  // against two launches (several microseconds each on PoCL): up to kWholeSolveWork
  // element-sigma pairs. Measured on PoCL, 2 cores (bench/RESULTS.md): the liver filter step
  // (596 x 4) 4.5 -> 2.3 ms, liver 4768 x 4 38 -> 28 ms; 596 x 16 equal; 4768 x 16 slower
  // (94 against 79 ms), as one core does what two did.
  whole_solve_ = !cg_per_group_ &&
                 (options.solve_launch == SolveLaunch::whole_solve ||
                  (options.solve_launch == SolveLaunch::automatic &&
                   static_cast<long long>(elements_) * S_ <= kWholeSolveWork));
  cg_group_ = cg_per_group_ ? 64 : 1;
  // The GPU form on a large mesh: P work-groups per sigma point in CG (conjugate_gradient.cl,
  // SF_CG_PARTITIONS), so that S x P groups share the device and each work-item takes about
  // kPartitionRows / 64 rows rather than thousands.
  if (cg_per_group_) cg_partitions_ = cg_partitions(nodes_, options.cg_partitions);
  const int units = static_cast<int>(std::max(1u, info.compute_units));
  cg_block_ = (S_ + units - 1) / units;
  while (S_ % cg_block_ != 0) --cg_block_;
  device_.build_program("-DSF_SIGMA_BLOCK=" + std::to_string(sigma_block_) +
                        " -DSF_ELEMENT_CHUNKS=" + std::to_string(element_chunks_) +
                        " -DSF_CG_PER_GROUP=" + std::to_string(cg_per_group_ ? 1 : 0) +
                        " -DSF_GROUP_SIZE=" + std::to_string(cg_group_) +
                        " -DSF_CG_BLOCK=" + std::to_string(cg_block_) +
                        " -DSF_CG_PARTITIONS=" + std::to_string(cg_partitions_));

  try {
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
    for (cl::Buffer* b : {&rhs_, &inverse_diagonal_, &r_, &z_, &d_, &q_})
      *b = make_buffer(dof, "CG vectors");
    frames_ = make_buffer(9 * per_element, "element frames");
    // Per-corner outputs of element_rhs (and of element_product on a GPU), or the chunks'
    // copies of K d on a CPU.
    element_out_ = make_buffer(std::max(12 * per_element, element_chunks_ * dof), "element outputs");
    element_diagonal_ = make_buffer(12 * per_element, "element diagonals");
    observations_ = make_buffer(std::max<std::size_t>(1, observed_.size()) * 3 * S_, "observations");
    for (cl::Buffer* b : {&bb_, &rr_, &rz_})
      *b = make_buffer(static_cast<std::size_t>(S_), "CG scalars");
    for (cl::Buffer* b : {&active_, &converged_, &iterations_})
      *b = make_buffer(std::vector<int>(S_, 0), "CG flags");
    all_active_ = make_buffer(std::vector<int>(S_, 1), "CG flags");
    if (cg_partitions_ > 1) {
      const std::size_t groups = static_cast<std::size_t>(S_) * cg_partitions_;
      partial_ = make_buffer(4 * groups, "CG partial sums");
      own_rz_ = make_buffer(groups, "CG scalars");
      const std::vector<int> flags(groups, 0);
      own_active_ = make_buffer(flags, "CG flags");
      own_iterations_ = make_buffer(flags, "CG flags");
    }
    recenter_scalars_ = make_buffer(1 + kDeviceMaxParameters, "re-centring");
    directions_ = make_buffer(static_cast<std::size_t>(kDeviceMaxParameters) * S_, "re-centring");
    weights_ = make_buffer(static_cast<std::size_t>(kDeviceMaxParameters) * S_, "re-centring");

    k_element_rhs_ = device_.kernel("element_rhs");
    k_node_rhs_ = device_.kernel("node_rhs");
    k_element_product_ = device_.kernel("element_product");
    k_node_product_ = device_.kernel("node_product");
    k_cg_start_ = device_.kernel("cg_start");
    k_cg_iteration_ = device_.kernel("cg_iteration");
    if (whole_solve_) k_cg_solve_ = device_.kernel("cg_solve");
    if (cg_partitions_ > 1) {
      k_cg_start_partials_ = device_.kernel("cg_start_partials");
      k_cg_start_scalars_ = device_.kernel("cg_start_scalars");
      k_cg_dot_ = device_.kernel("cg_dot");
      k_cg_update_ = device_.kernel("cg_update");
      k_cg_direction_ = device_.kernel("cg_direction");
    }
    k_state_update_ = device_.kernel("state_update");
    k_observation_gather_ = device_.kernel("observation_gather");
    k_recenter_ = device_.kernel("recenter");

    const cl_uint S = S_, E = elements_, N = nodes_, rows = 3 * nodes_;
    set_args(k_element_rhs_, S, E, element_nodes_, element_rest_, frames_, x_, v_, constants_,
             element_out_, element_diagonal_);
    set_args(k_node_rhs_, S, N, constants_, incidence_offsets_, incidence_, ligament_offsets_,
             ligament_of_node_, ligament_k_buffer_, control_k_, mass_, rest_positions_, x_, v_,
             element_out_, element_diagonal_, rhs_, inverse_diagonal_);
    // Arguments 5-6 (d, active) and 10 (d), 12 (q) are set per call.
    set_args(k_element_product_, S, E, element_nodes_, element_rest_, frames_);
    k_element_product_.setArg(7, element_out_);
    k_element_product_.setArg(8, N);
    k_element_product_.setArg(9, constants_);
    set_args(k_node_product_, S, N, constants_, incidence_offsets_, incidence_, ligament_offsets_,
             ligament_of_node_, ligament_k_buffer_, control_k_, mass_);
    k_node_product_.setArg(11, element_out_);
    set_args(k_cg_start_, S, N, constants_, q_, rhs_, inverse_diagonal_, r_, z_, d_, bb_, rr_,
             rz_, active_, converged_, iterations_);
    set_args(k_cg_iteration_, S, N, static_cast<cl_int>(model.solver.cg_max_iterations),
             constants_, inverse_diagonal_, dv_, r_, z_, d_, q_, bb_, rr_, rz_, active_,
             converged_, iterations_);
    if (!cg_per_group_) {  // the CPU form also does node_product's part (conjugate_gradient.cl)
      k_cg_iteration_.setArg(16, ligament_offsets_);
      k_cg_iteration_.setArg(17, ligament_of_node_);
      k_cg_iteration_.setArg(18, ligament_k_buffer_);
      k_cg_iteration_.setArg(19, control_k_);
      k_cg_iteration_.setArg(20, mass_);
      k_cg_iteration_.setArg(21, element_out_);
    }
    if (cg_partitions_ > 1) {
      set_args(k_cg_start_partials_, S, N, q_, rhs_, inverse_diagonal_, r_, z_, d_, partial_);
      set_args(k_cg_start_scalars_, S, constants_, partial_, bb_, rr_, rz_, active_, converged_,
               iterations_, own_active_, own_iterations_, own_rz_);
      set_args(k_cg_dot_, S, N, d_, q_, partial_, own_active_);
      set_args(k_cg_update_, S, N, inverse_diagonal_, dv_, r_, z_, d_, q_, partial_, own_active_,
               own_rz_);
      set_args(k_cg_direction_, S, N, static_cast<cl_int>(model.solver.cg_max_iterations),
               constants_, z_, d_, partial_, bb_, rr_, rz_, active_, converged_, iterations_,
               own_active_, own_iterations_, own_rz_);
    }
    if (whole_solve_)
      set_args(k_cg_solve_, S, E, N, static_cast<cl_int>(model.solver.cg_max_iterations),
               constants_, element_nodes_, element_rest_, frames_, ligament_offsets_,
               ligament_of_node_, ligament_k_buffer_, control_k_, mass_, rhs_,
               inverse_diagonal_, dv_, r_, z_, d_, q_, element_out_, bb_, rr_, rz_, active_,
               converged_, iterations_);
    set_args(k_state_update_, S, rows, constants_, bb_, dv_, x_, v_);
    set_args(k_observation_gather_, S, static_cast<cl_uint>(observed_.size()), observed_nodes_,
             observed_weights_, x_, observations_);
    set_args(k_recenter_, S, rows, static_cast<cl_uint>(estimated_.size()), recenter_scalars_,
             directions_, weights_, x_, v_);
    device_.queue().finish();
  } catch (const cl::Error& error) {
    throw opencl_failure("setting up the OpenCL ensemble", error);
  }
}

cl::Buffer OpenClEnsemble::make_buffer(std::size_t count, const char* what) {
  try {
    const std::size_t bytes = std::max<std::size_t>(1, count) * device_.real_size();
    device_bytes_ += bytes;
    return cl::Buffer(device_.context(), CL_MEM_READ_WRITE, bytes);
  } catch (const cl::Error& error) {
    throw opencl_failure(std::string("allocating ") + what, error);
  }
}

cl::Buffer OpenClEnsemble::make_buffer(const std::vector<double>& values, const char* what) {
  cl::Buffer buffer = make_buffer(values.size(), what);
  write(buffer, values);
  return buffer;
}

cl::Buffer OpenClEnsemble::make_buffer(const std::vector<int>& values, const char* what) {
  try {
    const std::size_t bytes = values.size() * sizeof(cl_int);
    device_bytes_ += bytes;
    cl::Buffer buffer(device_.context(), CL_MEM_READ_WRITE, bytes);
    device_.queue().enqueueWriteBuffer(buffer, CL_TRUE, 0, bytes, values.data());
    return buffer;
  } catch (const cl::Error& error) {
    throw opencl_failure(std::string("allocating ") + what, error);
  }
}

void OpenClEnsemble::write(const cl::Buffer& buffer, const std::vector<double>& values) const {
  if (values.empty()) return;
  const std::vector<unsigned char> bytes = to_device_reals(values, device_.precision());
  device_.queue().enqueueWriteBuffer(buffer, CL_TRUE, 0, bytes.size(), bytes.data());
}

std::vector<double> OpenClEnsemble::read(const cl::Buffer& buffer, std::size_t count) const {
  std::vector<unsigned char> bytes(count * device_.real_size());
  device_.queue().enqueueReadBuffer(buffer, CL_TRUE, 0, bytes.size(), bytes.data());
  return from_device_reals(bytes.data(), count, device_.precision());
}

std::vector<double> OpenClEnsemble::column_of(const cl::Buffer& buffer, std::size_t rows,
                                              int s) const {
  return sigma_column(read(buffer, rows * S_), rows, S_, s, "OpenClEnsemble");
}

void OpenClEnsemble::set_parameters(const Eigen::MatrixXd& theta) {
  check_parameter_matrix(theta, parameter_count(), sigma_count(), "OpenClEnsemble");
  set_ligament_stiffness(model_, estimated_, theta, S_, ligament_k_);
  write(ligament_k_buffer_, ligament_k_);
}

void OpenClEnsemble::write_step_constants(const Eigen::Vector3d& so_position) {
  write(constants_, step_constants_.next_step(model_, so_position));
}

void OpenClEnsemble::set_physics_effects(const std::vector<PhysicsEffects>& effects) {
  step_constants_.set_physics_effects(effects, "OpenClEnsemble");
}

void OpenClEnsemble::run(cl::Kernel& kernel, std::size_t items, std::size_t local) const {
  const std::size_t group = local > 0 ? local : kGroup;
  cl::Event event;
  device_.queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(round_up(items, group)),
                                       cl::NDRange(group), nullptr, &event);
  device_.record(kernel, event);
}

void OpenClEnsemble::run_cg(cl::Kernel& kernel) const {
  if (cg_per_group_)
    run(kernel, cg_group_ * S_, cg_group_);
  else
    run(kernel, static_cast<std::size_t>(S_ / cg_block_), 1);
}

void OpenClEnsemble::run_partitions(cl::Kernel& kernel) const {
  run(kernel, cg_group_ * S_ * cg_partitions_, cg_group_);
}

std::size_t OpenClEnsemble::element_items() const {
  return static_cast<std::size_t>(elements_) * (S_ / sigma_block_);
}

void OpenClEnsemble::element_rhs() { run(k_element_rhs_, element_items()); }

void OpenClEnsemble::node_rhs() { run(k_node_rhs_, static_cast<std::size_t>(nodes_) * S_); }

void OpenClEnsemble::element_product(const cl::Buffer& d, const cl::Buffer& active) {
  k_element_product_.setArg(5, d);
  k_element_product_.setArg(6, active);
  run(k_element_product_, element_chunks_ > 0 ? static_cast<std::size_t>(element_chunks_)
                                              : element_items(),
      element_chunks_ > 0 ? 1 : 0);
}

void OpenClEnsemble::node_product(const cl::Buffer& d, const cl::Buffer& q) {
  k_node_product_.setArg(10, d);
  k_node_product_.setArg(12, q);
  run(k_node_product_, static_cast<std::size_t>(nodes_) * (S_ / sigma_block_));
}

void OpenClEnsemble::conjugate_gradient() {
  if (whole_solve_) {
    run(k_cg_solve_, 1, 1);
    return;
  }
  // The warm start's residual (dv holds the last step's velocity change).
  element_product(dv_, all_active_);
  node_product(dv_, q_);
  if (cg_partitions_ > 1) {
    run_partitions(k_cg_start_partials_);
    run(k_cg_start_scalars_, static_cast<std::size_t>(S_));
  } else {
    run_cg(k_cg_start_);
  }
  // Iterate, checking on the host only now and then: first after as many iterations as the
  // last step needed (warm-started steps need about the same), then in small batches. A
  // sigma point that is done is left alone by the kernels, so overshooting changes nothing.
  const int cap = model_.solver.cg_max_iterations;
  int batch = std::max(1, expected_iterations_);
  std::vector<cl_uint> active(S_);
  for (int done = 0; done < cap;) {
    const int count = std::min(batch, cap - done);
    for (int i = 0; i < count; ++i) {
      element_product(d_, active_);
      if (cg_per_group_) node_product(d_, q_);   // on a CPU cg_iteration does it
      if (cg_partitions_ > 1) {
        run_partitions(k_cg_dot_);
        run_partitions(k_cg_update_);
        run_partitions(k_cg_direction_);
      } else {
        run_cg(k_cg_iteration_);
      }
    }
    done += count;
    device_.queue().enqueueReadBuffer(active_, CL_TRUE, 0, S_ * sizeof(cl_uint), active.data());
    if (std::none_of(active.begin(), active.end(), [](cl_uint a) { return a != 0; })) break;
    batch = std::max(2, expected_iterations_ / 8);
  }
}

StepReport OpenClEnsemble::advance(const Eigen::Vector3d& so_position) {
  const std::size_t dof = 3 * static_cast<std::size_t>(nodes_) * S_;
  StepReport report;
  try {
    write_step_constants(so_position);
    element_rhs();
    node_rhs();
    conjugate_gradient();
    run(k_state_update_, dof);
    // The solver report: four small reads, one wait.
    std::vector<cl_int> iterations(S_);
    std::vector<cl_uint> converged(S_);
    std::vector<unsigned char> rr_bytes(S_ * device_.real_size()), bb_bytes(rr_bytes.size());
    cl::CommandQueue& queue = device_.queue();
    queue.enqueueReadBuffer(iterations_, CL_FALSE, 0, S_ * sizeof(cl_int), iterations.data());
    queue.enqueueReadBuffer(converged_, CL_FALSE, 0, S_ * sizeof(cl_uint), converged.data());
    queue.enqueueReadBuffer(rr_, CL_FALSE, 0, rr_bytes.size(), rr_bytes.data());
    queue.enqueueReadBuffer(bb_, CL_FALSE, 0, bb_bytes.size(), bb_bytes.data());
    queue.finish();
    const Precision precision = device_.precision();
    report = solver_report(iterations, converged, from_device_reals(rr_bytes.data(), S_, precision),
                           from_device_reals(bb_bytes.data(), S_, precision));
    expected_iterations_ = *std::max_element(iterations.begin(), iterations.end());
  } catch (const cl::Error& error) {
    throw opencl_failure("advancing the OpenCL ensemble", error);
  }
  return report;
}

void OpenClEnsemble::predicted_observations(Eigen::MatrixXd& y) const {
  const std::size_t rows = observed_.size() * 3;
  if (rows == 0) {
    y.resize(0, S_);
    return;
  }
  try {
    run(k_observation_gather_, rows * S_);
    y = from_sigma_rows(read(observations_, rows * S_), rows, S_);
  } catch (const cl::Error& error) {
    throw opencl_failure("reading the observations", error);
  }
}

void OpenClEnsemble::recenter(const Recentering& r) {
  const RecenteringInputs in = pack_recentering(r, S_, "OpenClEnsemble");
  try {
    k_recenter_.setArg(2, static_cast<cl_uint>(in.p));
    write(recenter_scalars_, in.scalars);
    write(directions_, in.directions);
    write(weights_, in.weights);
    run(k_recenter_, 3 * static_cast<std::size_t>(nodes_));
  } catch (const cl::Error& error) {
    throw opencl_failure("re-centring the OpenCL ensemble", error);
  }
}

Eigen::VectorXd OpenClEnsemble::positions(int s) const {
  const std::vector<double> column = column_of(x_, 3 * static_cast<std::size_t>(nodes_), s);
  return Eigen::Map<const Eigen::VectorXd>(column.data(), static_cast<Eigen::Index>(column.size()));
}

Eigen::VectorXd OpenClEnsemble::velocities(int s) const {
  const std::vector<double> column = column_of(v_, 3 * static_cast<std::size_t>(nodes_), s);
  return Eigen::Map<const Eigen::VectorXd>(column.data(), static_cast<Eigen::Index>(column.size()));
}

std::vector<double> OpenClEnsemble::frames(int s) const {
  return column_of(frames_, 9 * static_cast<std::size_t>(elements_), s);
}

Eigen::MatrixXd OpenClEnsemble::system_product(const Eigen::MatrixXd& d) {
  const std::size_t rows = 3 * static_cast<std::size_t>(nodes_);
  if (static_cast<std::size_t>(d.rows()) != rows || d.cols() != S_)
    throw std::invalid_argument("OpenClEnsemble::system_product: expected 3N x S");
  try {
    write(d_, to_sigma_rows(d));
    element_product(d_, all_active_);
    node_product(d_, q_);
    return from_sigma_rows(read(q_, rows * S_), rows, S_);
  } catch (const cl::Error& error) {
    throw opencl_failure("the system product", error);
  }
}

std::string OpenClEnsemble::description() const {
  return device_ensemble_description("opencl", device_.precision(), device_.info().name);
}

}  // namespace sigmafem
