#include "host/opencl/opencl_ensemble.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "host/ensemble/device_readout.h"
#include "device_layout.h"
#include "step_constants.h"
#include "host/ensemble/device_limits.h"

namespace sigmafem {
namespace {

std::size_t round_up(std::size_t n, std::size_t multiple) {
  return (n + multiple - 1) / multiple * multiple;
}

}  // namespace

bool opencl_cpu_form(KernelForm form, const std::string& device_type) {
  return form == KernelForm::automatic ? device_type == "cpu" : form == KernelForm::cpu;
}

bool opencl_uses_factor(Preconditioner preconditioner, bool cpu_form) {
  return preconditioner == Preconditioner::factorised ||
         (preconditioner == Preconditioner::automatic && cpu_form);
}

bool opencl_uses_multigrid(Preconditioner preconditioner, bool cpu_form, bool nested) {
  return preconditioner == Preconditioner::multigrid ||
         (preconditioner == Preconditioner::automatic && !cpu_form && nested);
}

OpenClEnsemble::OpenClEnsemble(const Model& model, EstimatedParameters estimated,
                               ObservedPoints observed, int sigma_count,
                               const DeviceOptions& options)
    : DeviceEnsemble(model, std::move(estimated), std::move(observed), sigma_count,
                     options.precision, "opencl", "OpenClEnsemble"),
      device_(options.device, options.precision) {
  // Check the memory before asking for it, to say how much is needed (the factor's buffers,
  // when there is one, once it is analysed below).
  const OpenClDeviceInfo& info = device_.info();
  check_device_memory(info.name, info.global_memory, info.max_allocation, options);

  // The CPU form or the GPU form of the kernels (DeviceOptions::kernel_form): the device's
  // type decides unless a test forces one.
  const bool cpu_form = opencl_cpu_form(options.kernel_form, info.type);
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
  // (94 against 79 ms), as one core did what two did.
  whole_solve_ = !cg_per_group_ &&
                 (options.solve_launch == SolveLaunch::whole_solve ||
                  (options.solve_launch == SolveLaunch::automatic &&
                   static_cast<long long>(elements_) * S_ <= kWholeSolveWork));
  cg_group_ = cg_per_group_ ? 64 : 1;
  // The GPU form on a large mesh: CG's rows in P partitions (conjugate_gradient.cl,
  // SF_CG_PARTITIONS), a work-group for each partition and each SF_CG_SIGMA_LANES sigma points
  // side by side (CgGroups), so that many groups share the device, each work-item takes a few
  // rows rather than thousands, and a warp reads runs of consecutive entries.
  if (cg_per_group_) {
    const CgGroups groups = cg_groups(nodes_, S_, device_.real_size(), static_cast<int>(cg_group_),
                                      options.cg_partitions, options.cg_sigma_lanes);
    cg_partitions_ = groups.partitions;
    cg_sigma_lanes_ = groups.sigma_lanes;
    cg_sigma_blocks_ = (S_ + cg_sigma_lanes_ - 1) / cg_sigma_lanes_;
  }
  const int units = static_cast<int>(std::max(1u, info.compute_units));
  int per_unit = (S_ + units - 1) / units;
  while (S_ % per_unit != 0) --per_unit;
  // The CG kernels' blocks work on the ensemble's rows, [row S + s]: blocks that share a
  // row's cache line write into each other's lines at every row, and two work-items doing so
  // were slower than one doing both (bench/RESULTS.md, stop 46, when the factor's work vector
  // was shared too: the 38k liver's cg_iteration at S = 4 30 -> 18 ms, the 4768 liver's at
  // S = 16 3.4 -> 2.1 ms). So a block per compute unit only where each fills whole cache lines
  // (S = 32 and up in float), else one; with a factor at any S (below, where it is decided).
  const unsigned line = info.cache_line > 0 ? info.cache_line : 64;
  const bool whole_lines = (per_unit * device_.real_size()) % line == 0;
  // cg_solve's blocks work on vectors of their own: a block per compute unit where each has
  // at least 4 sigma points, else one. Measured on PoCL, 2 cores (stop 46): the liver at S = 16
  // in two blocks of 8, an ensemble step 2.4-2.7 -> 1.4-1.6 ms (factor); the liver filter
  // step (S = 4) in two blocks of 2, its solve 0.7 -> 1.8 ms: loops over two sigma points
  // were not vectorised.
  solve_block_ = per_unit >= 4 ? per_unit : S_;
  // A factor of the representative's system shared by the sigma points, in the CPU form's
  // CG (the GPU form has Jacobi only); analysed here for its size, made at the first step
  // and again when due.
  if (opencl_uses_factor(options.preconditioner, cpu_form)) {
    if (!cpu_form)
      throw DeviceError("--preconditioner factorised: OpenCL has it on a CPU device only (its "
                        "GPU kernels precondition CG with the multigrid V-cycle or Jacobi); device " + info.name);
    // The shared factor is corrected for each sigma point's own springs at the estimated
    // ligaments' rows (SpringCorrection) where the kernels' arrays of m x S stay small.
    SpringCorrection correction = spring_correction(options.spring_correction);
    const bool corrected = correction.size() > 0;
    // Each sigma point its own factor where the S copies of L's values stay small enough for a
    // CPU's cache, from kOwnFactorsFromSigmaPoints, and where the sigma points differ by more
    // than the springs the shared factor is corrected for: those that differ by region moduli
    // are preconditioned less well by the mean's factor (the liver's filter step with 13
    // region moduli, S = 17: 12.7 CG iterations shared, 2.8 own; bench/RESULTS.md, stop 49),
    // while by springs alone the corrected one is as good and reads one L for a block (the
    // liver at S = 16: 2.6 iterations and 1.2-1.3 ms a step against own factors' 2.2 and
    // 2.0-2.9 ms; stop 51). Beyond the cache a solve's time is reading L, which the shared
    // factor reads once for a block.
    const bool springs_alone = corrected && estimated_.regions.empty();
    // Own factors (in the free ordering) are sized by an analysis first; else the shared factor
    // is analysed once, with the springs' rows last where it is corrected (~1 s on the 38k liver).
    const bool may_own = !springs_alone && S_ >= kOwnFactorsFromSigmaPoints;
    factor_ = corrected && !may_own ? analysed_factor(correction) : analysed_factor();
    if (may_own && static_cast<std::size_t>(S_) * factor_->nonzeros() * device_.real_size() <= options.own_factors_bytes)
      factor_copies_ = S_;
    if (factor_copies_ == 1 && corrected) {
      springs_ = std::move(correction);
      if (may_own) factor_ = analysed_factor(springs_);   // again, the springs' rows last
    }
    // Again with the factor's buffers (L alone is 125 MB on the 38k liver; the copies of its
    // values add at most own_factors_bytes).
    check_device_memory_with_factor(factor_->nonzeros(), FactorStorage::columns, factor_copies_);
    preconditioner_making_.set_rule(options.background_making_steps, options.background_making_solves);
    // The copies in the layout of the blocks that solve with them (conjugate_gradient.cl): cg_solve's
    // blocks of their own vectors one after the other, else all S interleaved.
    factor_block_ = whole_solve_ && solve_block_ < S_ ? solve_block_ : S_;
  }
  // The GPU form's multigrid V-cycle, on the refinements that made the mesh.
  std::vector<RowMajorMatrix> prolongations;
  if (options.preconditioner == Preconditioner::multigrid || (options.preconditioner == Preconditioner::automatic && !cpu_form))
    prolongations = nested_prolongations(model_);
  if (opencl_uses_multigrid(options.preconditioner, cpu_form, !prolongations.empty())) {
    if (cpu_form)
      throw DeviceError("--preconditioner multigrid: OpenCL has it in its GPU kernels only (a CPU device "
                        "has the factor); device " + info.name);
    if (prolongations.empty())
      throw DeviceError("--preconditioner multigrid: the mesh is not a uniform refinement of a coarser one "
                        "(a scenario's mesh.refine makes one)");
    multigrid_ = std::make_unique<NestedMultigrid>(std::move(prolongations));
    shift_rows_ = SpringCorrection(estimated_spring_rows(model_, estimated_));
    multigrid_refresh_.fix_cost(options.multigrid_making_cycles);
    preconditioner_making_.set_rule(options.background_making_steps, kBackgroundMultigridCycles);
  }
  cg_partitioned_ = cg_per_group_ && (cg_partitions_ > 1 || multigrid_);
  // With a factor the solve is most of an iteration, and each block solves with a work vector
  // of its own (conjugate_gradient.cl): a block per compute unit then pays at any S
  // (bench/RESULTS.md, stop 50: the 117k box at S = 16 1155-1222 -> 648-826 ms a step, the 38k
  // liver's filter step 199-210 -> 183-189 ms).
  cg_block_ = whole_lines || factor_ ? per_unit : S_;
  device_.build_program("-DSF_SIGMA_BLOCK=" + std::to_string(sigma_block_) +
                        " -DSF_ELEMENT_CHUNKS=" + std::to_string(element_chunks_) +
                        " -DSF_CG_PER_GROUP=" + std::to_string(cg_per_group_ ? 1 : 0) +
                        " -DSF_GROUP_SIZE=" + std::to_string(cg_group_) +
                        " -DSF_CG_BLOCK=" + std::to_string(cg_block_) +
                        " -DSF_CG_SOLVE_BLOCK=" + std::to_string(solve_block_) +
                        " -DSF_CG_SOLVE_VECTORS=" + std::to_string(kCgSolveBlockVectors) +
                        " -DSF_CG_PARTITIONS=" + std::to_string(cg_partitions_) +
                        " -DSF_CG_SIGMA_LANES=" + std::to_string(cg_sigma_lanes_) +
                        " -DSF_FACTOR=" + std::to_string(factor_ ? 1 : 0) +
                        " -DSF_FACTOR_PER_SIGMA=" + std::to_string(factor_copies_ > 1 ? 1 : 0) +
                        " -DSF_SPRING_ROWS=" + std::to_string(springs_.size()) +
                        " -DSF_POLAR_FRAMES=" +
                        std::to_string(model_.material.rotation == ElementRotation::polar ? 1 : 0));

  using B = DeviceBuffer;
  try {
    // The chunks' copies of K d on a CPU live in the element outputs (element_product.cl).
    const std::size_t dof = 3 * static_cast<std::size_t>(nodes_) * S_;
    // cg_solve's blocks keep their own vectors there too (conjugate_gradient.cl).
    const std::size_t cg_solve_vectors = whole_solve_ && solve_block_ < S_ ? kCgSolveBlockVectors : 0;
    DeviceBufferSizes sizes{std::max<std::size_t>(element_chunks_, cg_solve_vectors) * dof,
                            cg_partitions_,
                            factor_ ? factor_->nonzeros() : 0, factor_copies_,
                            springs_.size()};
    sizes.jacobi_diagonals = factor_ == nullptr;   // SF_FACTOR's kernels leave them out
    written_.resize(kDeviceBufferCount);
    write_done_.resize(written_.size());
    for (const DeviceBufferSpec& spec : buffer_specs(sizes)) {
      const std::size_t bytes = take_device_bytes(spec, device_.real_size());
      buffers_.emplace_back(device_.context(), CL_MEM_READ_WRITE, bytes);
      if (spec.integer && !spec.integers.empty())
        device_.queue().enqueueWriteBuffer(buffers_.back(), CL_TRUE, 0, bytes, spec.integers.data());
      if (!spec.reals.empty()) write_reals(spec.id, spec.reals);
    }

    k_element_rhs_ = device_.kernel("element_rhs");
    k_node_rhs_ = device_.kernel("node_rhs");
    k_element_product_ = device_.kernel("element_product");
    k_node_product_ = device_.kernel("node_product");
    k_cg_start_ = device_.kernel("cg_start");
    k_cg_iteration_ = device_.kernel("cg_iteration");
    if (whole_solve_) k_cg_solve_ = device_.kernel("cg_solve");
    if (cg_partitioned_) {
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
    const cl_int cap = model.solver.cg_max_iterations;
    set_arguments(k_element_rhs_, kernel_buffers(DeviceKernel::element_rhs), S, E);
    set_arguments(k_node_rhs_, kernel_buffers(DeviceKernel::node_rhs), S, N);
    set_arguments(k_element_product_, kernel_buffers(DeviceKernel::element_product), S, E, N);
    set_arguments(k_node_product_, kernel_buffers(DeviceKernel::node_product), S, N);
    set_arguments(k_state_update_, kernel_buffers(DeviceKernel::state_update), S, rows);
    set_arguments(k_observation_gather_, kernel_buffers(DeviceKernel::observation_gather), S,
                  static_cast<cl_uint>(observed_.size()));
    set_arguments(k_recenter_, kernel_buffers(DeviceKernel::recenter), S, rows,
                  static_cast<cl_uint>(estimated_.count()));
    // The CG kernels' buffers (conjugate_gradient.cl).
    // The factor's buffers, last, where the CPU form's CG has them (SF_FACTOR).
    const std::vector<DeviceBuffer> factor =
        factor_ ? std::vector<DeviceBuffer>{B::factor_columns, B::factor_rows, B::factor_values,
                                            B::factor_order, B::factor_work, B::spring_at,
                                            B::spring_solves, B::spring_coupling}
                : std::vector<DeviceBuffer>{};
    std::vector<DeviceBuffer> start = {B::constants, B::q, B::rhs, B::inverse_diagonal, B::r, B::z,
                                       B::d, B::bb, B::rr, B::rz, B::active, B::converged,
                                       B::iterations};
    start.insert(start.end(), factor.begin(), factor.end());
    set_arguments(k_cg_start_, start, S, N);
    std::vector<DeviceBuffer> iteration = {B::constants, B::inverse_diagonal, B::dv, B::r, B::z,
                                           B::d, B::q, B::bb, B::rr, B::rz, B::active,
                                           B::converged, B::iterations};
    if (!cg_per_group_)   // the CPU form also does node_product's part
      iteration.insert(iteration.end(), {B::ligament_offsets, B::ligament_of_node, B::ligament_k,
                                         B::control_k, B::mass, B::element_out});
    iteration.insert(iteration.end(), factor.begin(), factor.end());
    set_arguments(k_cg_iteration_, iteration, S, N, cap);
    if (cg_partitioned_) {
      set_arguments(k_cg_start_partials_, {B::q, B::rhs, B::inverse_diagonal, B::r, B::z, B::d, B::partial},
                    S, N);
      set_arguments(k_cg_start_scalars_, {B::constants, B::partial, B::bb, B::rr, B::rz, B::active,
                                          B::converged, B::iterations, B::own_active,
                                          B::own_iterations, B::own_rz}, S);
      set_arguments(k_cg_dot_, {B::d, B::q, B::partial, B::own_active}, S, N);
      set_arguments(k_cg_update_, {B::inverse_diagonal, B::dv, B::r, B::z, B::d, B::q, B::partial,
                                   B::own_active, B::own_rz}, S, N);
      set_arguments(k_cg_direction_, {B::constants, B::z, B::d, B::partial, B::bb, B::rr, B::rz,
                                      B::active, B::converged, B::iterations, B::own_active,
                                      B::own_iterations, B::own_rz}, S, N, cap);
    }
    if (multigrid_) {
      k_cg_preconditioned_ = device_.kernel("cg_preconditioned");
      set_arguments(k_cg_preconditioned_, {B::r, B::z, B::d, B::partial, B::own_active}, S, N, cl_uint{0});
      device_multigrid_ = std::make_unique<OpenClMultigrid>(device_, S_);
    }
    if (whole_solve_) {
      std::vector<DeviceBuffer> solve = {B::constants, B::element_nodes, B::element_rest, B::frames,
                                         B::ligament_offsets, B::ligament_of_node, B::ligament_k,
                                         B::control_k, B::mass, B::rhs, B::inverse_diagonal, B::dv,
                                         B::r, B::z, B::d, B::q, B::element_out, B::bb, B::rr,
                                         B::rz, B::active, B::converged, B::iterations};
      solve.insert(solve.end(), factor.begin(), factor.end());
      set_arguments(k_cg_solve_, solve, S, E, N, cap);
    }
    device_.queue().finish();
  } catch (const cl::Error& error) {
    throw opencl_failure("setting up the OpenCL ensemble", error);
  }
}

template <class... Scalars>
void OpenClEnsemble::set_arguments(cl::Kernel& kernel, const std::vector<DeviceBuffer>& buffers,
                                   const Scalars&... scalars) {
  cl_uint index = 0;
  (kernel.setArg(index++, scalars), ...);
  for (DeviceBuffer id : buffers) kernel.setArg(index++, buffer(id));
}

OpenClEnsemble::~OpenClEnsemble() {
  try {
    device_.queue().finish();
  } catch (const cl::Error&) {   // nothing to report to from a destructor; the copies go
  }
}

void OpenClEnsemble::write_reals(DeviceBuffer id, const std::vector<double>& values) {
  if (values.empty()) return;
  observations_ready_ = false;
  const auto slot = static_cast<std::size_t>(id);
  try {
    if (write_done_[slot]()) write_done_[slot].wait();   // its last write has read the copy
    written_[slot] = to_device_reals(values, device_.precision());
    device_.queue().enqueueWriteBuffer(buffer(id), CL_FALSE, 0, written_[slot].size(),
                                       written_[slot].data(), nullptr, &write_done_[slot]);
  } catch (const cl::Error& error) {
    throw opencl_failure("writing to the device", error);
  }
}

std::vector<double> OpenClEnsemble::read_reals(DeviceBuffer id, std::size_t count) const {
  std::vector<unsigned char> bytes(count * device_.real_size());
  try {
    device_.queue().enqueueReadBuffer(buffer(id), CL_TRUE, 0, bytes.size(), bytes.data());
  } catch (const cl::Error& error) {
    throw opencl_failure("reading from the device", error);
  }
  return from_device_reals(bytes.data(), count, device_.precision());
}

void OpenClEnsemble::upload_ligament_k() {
  write_reals(DeviceBuffer::ligament_k, ligament_k_);
  coupling_stale_ = springs_.prepared();   // the springs' corrections follow the stiffnesses
  shift_stale_ = multigrid_makings_ > 0;
}

void OpenClEnsemble::run(cl::Kernel& kernel, std::size_t items, std::size_t local) const {
  const std::size_t group = local > 0 ? local : SF_ITEMS_PER_GROUP;
  cl::Event event;
  device_.queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange(round_up(items, group)),
                                       cl::NDRange(group), nullptr, &event);
  device_.record(kernel, event);
}

void OpenClEnsemble::run_cg(cl::Kernel& kernel) const {
  if (cg_per_group_)
    run(kernel, cg_group_ * cg_sigma_blocks_, cg_group_);
  else
    run(kernel, static_cast<std::size_t>(S_ / cg_block_), 1);
}

void OpenClEnsemble::run_partitions(cl::Kernel& kernel) const {
  run(kernel, cg_group_ * cg_sigma_blocks_ * cg_partitions_, cg_group_);
}

void OpenClEnsemble::run_elements(cl::Kernel& kernel) const {
  if (element_chunks_ > 0)
    run(kernel, static_cast<std::size_t>(element_chunks_), 1);
  else
    run(kernel, static_cast<std::size_t>(elements_) * (S_ / sigma_block_));
}

void OpenClEnsemble::element_product(DeviceBuffer d, DeviceBuffer active) {
  const cl_uint scalars = 3;   // S, E, N
  k_element_product_.setArg(scalars + buffer_slot(DeviceKernel::element_product, DeviceBuffer::d), buffer(d));
  k_element_product_.setArg(scalars + buffer_slot(DeviceKernel::element_product, DeviceBuffer::active),
                            buffer(active));
  run_elements(k_element_product_);
}

void OpenClEnsemble::node_product(DeviceBuffer d) {
  k_node_product_.setArg(2 + buffer_slot(DeviceKernel::node_product, DeviceBuffer::d), buffer(d));
  run(k_node_product_, static_cast<std::size_t>(nodes_) * (S_ / sigma_block_));
}

void OpenClEnsemble::conjugate_gradient() {
  if (whole_solve_) {
    run(k_cg_solve_, static_cast<std::size_t>(S_ / solve_block_), 1);
    return;
  }
  // The warm start's residual (dv holds the last step's velocity change).
  element_product(DeviceBuffer::dv, DeviceBuffer::all_active);
  node_product(DeviceBuffer::dv);
  if (cg_partitioned_) {
    run_partitions(k_cg_start_partials_);
    precondition_outside(true);
    run(k_cg_start_scalars_, static_cast<std::size_t>(S_));
  } else {
    run_cg(k_cg_start_);
  }
  std::vector<cl_uint> active(S_);
  iterate_in_batches([&](int count) {
    for (int i = 0; i < count; ++i) {
      element_product(DeviceBuffer::d, DeviceBuffer::active);
      if (cg_per_group_) node_product(DeviceBuffer::d);   // on a CPU cg_iteration does it
      if (cg_partitioned_) {
        run_partitions(k_cg_dot_);
        run_partitions(k_cg_update_);
        precondition_outside(false);
        run_partitions(k_cg_direction_);
      } else {
        run_cg(k_cg_iteration_);
      }
    }
    device_.queue().enqueueReadBuffer(buffer(DeviceBuffer::active), CL_TRUE, 0, S_ * sizeof(cl_uint),
                                      active.data());
    return std::any_of(active.begin(), active.end(), [](cl_uint a) { return a != 0; });
  });
}

void OpenClEnsemble::precondition_outside(bool start) {
  // Until a hierarchy has gone down, the Jacobi z that cg_start_partials and cg_update made.
  if (multigrid_makings_ == 0) return;
  device_multigrid_->enqueue(buffer(DeviceBuffer::r), buffer(DeviceBuffer::z));
  k_cg_preconditioned_.setArg(2, static_cast<cl_uint>(start ? 1 : 0));
  run_partitions(k_cg_preconditioned_);
}

StepReport OpenClEnsemble::advance(const Eigen::Vector3d& so_position) {
  const std::size_t dof = 3 * static_cast<std::size_t>(nodes_) * S_;
  StepReport report;
  const int factorisations_before = factorisations();
  try {
    const std::vector<double> constants = step_constants_.next_step(model_, so_position);
    if (preconditioner_making_.pending()) {
      bool made = false;
      if (preconditioner_making_.hand_over(made)) hand_over_making(made);
    } else if (factor_ && factor_->due()) {
      refresh_factor(constants);
    } else if (multigrid_ && multigrid_refresh_.due()) {
      refresh_multigrid(constants);
    }
    write_reals(DeviceBuffer::constants, constants);
    if (coupling_stale_) upload_spring_coupling(constants);
    if (shift_stale_) upload_multigrid_shift(constants);
    run_elements(k_element_rhs_);
    run(k_node_rhs_, static_cast<std::size_t>(nodes_) * S_);
    conjugate_gradient();
    run(k_state_update_, dof);
    // The solver report: four small reads, one wait.
    std::vector<cl_int> iterations(S_);
    std::vector<cl_uint> converged(S_);
    std::vector<unsigned char> rr_bytes(S_ * device_.real_size()), bb_bytes(rr_bytes.size());
    cl::CommandQueue& queue = device_.queue();
    queue.enqueueReadBuffer(buffer(DeviceBuffer::iterations), CL_FALSE, 0, S_ * sizeof(cl_int), iterations.data());
    queue.enqueueReadBuffer(buffer(DeviceBuffer::converged), CL_FALSE, 0, S_ * sizeof(cl_uint), converged.data());
    queue.enqueueReadBuffer(buffer(DeviceBuffer::rr), CL_FALSE, 0, rr_bytes.size(), rr_bytes.data());
    queue.enqueueReadBuffer(buffer(DeviceBuffer::bb), CL_FALSE, 0, bb_bytes.size(), bb_bytes.data());
    enqueue_observations();
    queue.finish();
    observations_ready_ = !observed_.empty();
    const Precision precision = device_.precision();
    report = step_report(iterations, converged, from_device_reals(rr_bytes.data(), S_, precision),
                         from_device_reals(bb_bytes.data(), S_, precision));
    // Not while a preconditioner is being made (the rule counts from the step it is handed over).
    if (!preconditioner_making_.pending()) {
      const int most = *std::max_element(iterations.begin(), iterations.end());
      if (factor_) factor_->record(most);
      if (multigrid_) multigrid_refresh_.record(most);
    }
    report.factorisations = factorisations() - factorisations_before;
  } catch (const cl::Error& error) {
    throw opencl_failure("advancing the OpenCL ensemble", error);
  }
  return report;
}

void OpenClEnsemble::refresh_factor(const std::vector<double>& constants) {
  if (factor_copies_ == 1) {
    // A large factor in the background where the device has one to step on meanwhile; a failed
    // making leaves that one in place, and the rule asks again at the next step.
    if (on_device_ == FactorOnDevice::factor && preconditioner_making_.takes(factor_->factorisation_in_solves())) {
      making_springs_ = factorised_springs(springs_, constants);
      preconditioner_making_.start([this, system = representative_system_later()] { return factor_->factorise(system()); });
      return;
    }
    const Eigen::SparseMatrix<double> A = representative_system();
    if (!factor_->factorise(A)) return fall_back_to_diagonal(A);
    return upload_factor(factorised_springs(springs_, constants));
  }
  // Each sigma point's own system at its own state, factorised on the same analysis (the
  // pattern is the assembly's, the same for all).
  Eigen::MatrixXd X, V;
  read_states(X, V);
  std::vector<double> values(factor_->nonzeros() * static_cast<std::size_t>(S_));
  for (int s = 0; s < S_; ++s) {
    if (!factor_->factorise(sigma_system(s, X.col(s), V.col(s)))) return fall_back_to_diagonal(representative_system());
    const double* L = factor_->lower().valuePtr();
    for (std::size_t k = 0; k < factor_->nonzeros(); ++k) values[factor_value_index(s, k, factor_->nonzeros())] = L[k];
  }
  upload_factor_pattern();
  write_reals(DeviceBuffer::factor_values, values);
  factor_makings_ += S_;
}

void OpenClEnsemble::upload_factor(const std::vector<double>& springs) {
  const Eigen::SparseMatrix<double>& L = factor_->lower();
  if (springs_.size() > 0) prepare_spring_correction(springs);
  upload_factor_pattern();
  write_reals(DeviceBuffer::factor_values, std::vector<double>(L.valuePtr(), L.valuePtr() + L.nonZeros()));
  ++factor_makings_;
}

void OpenClEnsemble::upload_factor_pattern() {
  // The factor's pattern and ordering are the same at every refresh (the representative's
  // assembly pattern does not change, so neither does the analysis): only the values go down
  // again.
  if (on_device_ != FactorOnDevice::factor) {
    const Eigen::SparseMatrix<double>& L = factor_->lower();
    const std::size_t rows = static_cast<std::size_t>(L.cols());
    write_integers(DeviceBuffer::factor_columns, L.outerIndexPtr(), rows + 1);
    write_integers(DeviceBuffer::factor_rows, L.innerIndexPtr(), static_cast<std::size_t>(L.nonZeros()));
    write_integers(DeviceBuffer::factor_order, factor_->order(), rows);
  }
  on_device_ = FactorOnDevice::factor;
}

void OpenClEnsemble::hand_over_making(bool made) {
  if (factor_) {
    if (made) upload_factor(making_springs_);
    return;
  }
  multigrid_refresh_.made(made, multigrid_->setup_in_cycles());
  if (made) upload_multigrid(making_springs_);
}

void OpenClEnsemble::refresh_multigrid(const std::vector<double>& constants) {
  // Made in the background where the device has a hierarchy to step on meanwhile; a failed
  // making leaves that one in place, and the rule asks again at the next step.
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

void OpenClEnsemble::upload_multigrid(const std::vector<double>& springs) {
  // The first making's buffers: later ones are written into them.
  const bool first = multigrid_makings_ == 0;
  if (first) check_more_device_memory(multigrid_memory(*multigrid_, S_, device_.real_size()), "the multigrid levels");
  device_multigrid_->upload(*multigrid_);
  if (first) device_bytes_ += device_multigrid_->device_bytes();
  ++multigrid_makings_;
  multigrid_springs_ = springs;
  shift_stale_ = true;
}

void OpenClEnsemble::upload_multigrid_shift(const std::vector<double>& constants) {
  device_multigrid_->upload_shift(spring_shift_rows(shift_rows_, constants, multigrid_springs_));
  shift_stale_ = false;
}

void OpenClEnsemble::prepare_spring_correction(const std::vector<double>& springs) {
  springs_.prepare(*factor_);
  factorised_springs_ = springs;
  const std::vector<int>& reached = springs_.reached();
  std::vector<int> at = {static_cast<int>(reached.size())};
  at.insert(at.end(), reached.begin(), reached.end());
  write_integers(DeviceBuffer::spring_at, at.data(), at.size());
  const Eigen::MatrixXd& V = springs_.reached_values();
  std::vector<double> values(static_cast<std::size_t>(V.size()));   // by rows
  for (Eigen::Index u = 0; u < V.rows(); ++u)
    for (Eigen::Index j = 0; j < V.cols(); ++j) values[static_cast<std::size_t>(u * V.cols() + j)] = V(u, j);
  write_reals(DeviceBuffer::spring_solves, values);
  coupling_stale_ = true;
}

void OpenClEnsemble::upload_spring_coupling(const std::vector<double>& constants) {
  write_reals(DeviceBuffer::spring_coupling, spring_couplings(springs_, constants, factorised_springs_));
  coupling_stale_ = false;
}

std::size_t OpenClEnsemble::factor_value_index(int s, std::size_t k, std::size_t nonzeros) const {
  if (factor_copies_ == 1) return k;
  const std::size_t block = static_cast<std::size_t>(factor_block_), sigma = static_cast<std::size_t>(s);
  return (sigma / block) * nonzeros * block + k * block + sigma % block;
}

void OpenClEnsemble::fall_back_to_diagonal(const Eigen::SparseMatrix<double>& A) {
  // A matrix that is not positive definite (a diverged state?) leaves the last factor in
  // place, and the next step tries again.
  if (on_device_ == FactorOnDevice::none) upload_diagonal_factor(A);
}

void OpenClEnsemble::upload_diagonal_factor(const Eigen::SparseMatrix<double>& A) {
  const int rows = static_cast<int>(A.rows());
  std::vector<int> columns(static_cast<std::size_t>(rows) + 1), order(static_cast<std::size_t>(rows));
  for (int i = 0; i < rows; ++i) {
    columns[static_cast<std::size_t>(i)] = i;
    order[static_cast<std::size_t>(i)] = i;
  }
  const std::vector<double> values = diagonal_stand_in(A);
  columns.back() = rows;
  write_integers(DeviceBuffer::factor_columns, columns.data(), columns.size());
  write_integers(DeviceBuffer::factor_rows, order.data(), order.size());   // row i: i
  write_integers(DeviceBuffer::factor_order, order.data(), order.size());
  // The same diagonal for every sigma point when each has its own factor.
  std::vector<double> copies(values.size() * static_cast<std::size_t>(factor_copies_));
  for (int s = 0; s < factor_copies_; ++s)
    for (std::size_t k = 0; k < values.size(); ++k) copies[factor_value_index(s, k, values.size())] = values[k];
  write_reals(DeviceBuffer::factor_values, copies);
  on_device_ = FactorOnDevice::diagonal;
}

void OpenClEnsemble::write_integers(DeviceBuffer id, const int* data, std::size_t count) {
  device_.queue().enqueueWriteBuffer(buffer(id), CL_TRUE, 0, count * sizeof(cl_int), data);
}

void OpenClEnsemble::predicted_observations(Eigen::MatrixXd& y) const {
  const std::size_t rows = observed_.size() * 3;
  if (rows == 0) {
    y.resize(0, S_);
    return;
  }
  try {
    if (!observations_ready_) {
      enqueue_observations();
      device_.queue().finish();
      observations_ready_ = true;
    }
    y = from_sigma_rows(from_device_reals(observation_bytes_.data(), rows * S_, device_.precision()),
                        rows, S_);
  } catch (const cl::Error& error) {
    throw opencl_failure("reading the observations", error);
  }
}

void OpenClEnsemble::enqueue_observations() const {
  const std::size_t rows = observed_.size() * 3;
  if (rows == 0) return;
  run(k_observation_gather_, rows * S_);
  observation_bytes_.resize(rows * S_ * device_.real_size());
  device_.queue().enqueueReadBuffer(buffer(DeviceBuffer::observations), CL_FALSE, 0,
                                    observation_bytes_.size(), observation_bytes_.data());
}

void OpenClEnsemble::recenter(const Recentering& r) {
  const RecenteringInputs in = pack_recentering(r, S_, "OpenClEnsemble");
  observations_ready_ = false;
  try {
    k_recenter_.setArg(2, static_cast<cl_uint>(in.p));
    write_reals(DeviceBuffer::recenter_scalars, in.scalars);
    write_reals(DeviceBuffer::directions, in.directions);
    write_reals(DeviceBuffer::weights, in.weights);
    run(k_recenter_, 3 * static_cast<std::size_t>(nodes_));
  } catch (const cl::Error& error) {
    throw opencl_failure("re-centring the OpenCL ensemble", error);
  }
}

void OpenClEnsemble::run_system_product() {
  try {
    element_product(DeviceBuffer::d, DeviceBuffer::all_active);
    node_product(DeviceBuffer::d);
  } catch (const cl::Error& error) {
    throw opencl_failure("the system product", error);
  }
}

}  // namespace sigmafem
