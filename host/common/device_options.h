// DeviceOptions: how a device back end runs (`--device N --precision single|double`, and
// the choices tests and benchmarks force: the CG launch and the kernels' form).
#pragma once

#include <cstddef>

namespace sigmafem {

// The arithmetic of a device ensemble: float32 by default; float64 where the device has it.
enum class Precision { single, double_precision };

// Bytes of one device real in that arithmetic.
inline std::size_t real_size(Precision precision) {
  return precision == Precision::single ? sizeof(float) : sizeof(double);
}

// How a device back end runs its CG solve: a few launches per iteration (products over all
// sigma points at once, on every core), the whole solve in one launch (no launch cost per
// iteration, one core), or the back end's choice by mesh size and S.
enum class SolveLaunch { automatic, per_iteration, whole_solve };

// Which device and precision a device back end uses (`--device N --precision single|double`).
// The form of the OpenCL kernels (host/opencl/opencl_ensemble.cpp): the CPU form (element
// chunks, blocks of sigma points per work-item), the GPU form (a work-item per element and
// sigma point, a work-group per sigma point in CG), or the one for the device's type. Forcing
// the GPU form on PoCL lets the tests run it where there is no GPU. The Vulkan shaders' CPU
// form reads their read-only arrays through texel buffers, the GPU form through storage
// buffers (vulkan_texel_reads, host/vulkan/vulkan_ensemble.h).
enum class KernelForm { automatic, cpu, gpu };

// CG's preconditioner: Jacobi (the oracle's and the device kernels'), or sparse Cholesky
// factors, one per sigma point of the CPU ensemble or one they share (CpuEnsemble,
// host/reference/factorised_preconditioner.h), or on OpenCL's CPU form and Vulkan on a CPU
// device one factor of the mean sigma point's system that all share (OpenClEnsemble,
// VulkanFactorSolve), or a multigrid V-cycle on the meshes of a uniform refinement
// (host/reference/nested_multigrid.h; OpenCL's GPU form and Vulkan, OpenClMultigrid and
// VulkanMultigrid); automatic is the factors on the CPU back end, OpenCL's CPU form and Vulkan
// on a CPU device, on a GPU the V-cycle where the mesh is a refinement, else Jacobi.
enum class Preconditioner { automatic, jacobi, factorised, multigrid };

// Own factors pay from this many sigma points (bench/RESULTS.md, stop 49, the liver's filter
// step on PoCL): at S = 4 they halved the CG iterations but not the time (1.36-1.54 ms against
// 1.05-1.27 shared: S factorisations a refresh), at S = 17 5.6 against 7.2 ms, at S = 65 24
// against 45.
constexpr int kOwnFactorsFromSigmaPoints = 16;

// The most spring rows times sigma points for which OpenCL's shared factor is corrected for
// each sigma point's own springs (DeviceOptions::spring_correction; its kernels keep two
// arrays of that many reals per work-item).
constexpr std::size_t kSpringRowsTimesSigmaPoints = 4096;

// A shared factor whose making is the work of at least this many solves with it
// (FactorisedPreconditioner::factorisation_in_solves) is made again on a host thread while the
// ensemble steps on with the last one (host/reference/background_making.h): the 38k liver's
// (322; made at once, its making stopped a step for 1.5-1.85 s on PoCL) and the 117k
// box's (711), not the 4768 liver's (104), the box's (55) or the liver's (35), made in tens of
// milliseconds or less: they are made at once as before. Measured the other way on the 4768
// liver (2000 steps on PoCL, bench/RESULTS.md, stop 63): in the background its slowest step
// 35 -> 16 ms, but its mean 3.5 -> 3.8 ms (CG on an older factor).
constexpr double kBackgroundMakingSolves = 200.0;
// And handed over this many steps after it began. The 38k liver on PoCL, 2 cores shared with
// the making (bench/RESULTS.md, stop 62): 10 steps waited for it at 3 of 9 hand-overs (up to
// 0.86 s), 20 at none; 50 kept CG on a staler factor longer (a step 111 ms on average against
// 88 with 20 and 81 made at once, when a making stopped its step for 1.5-1.85 s).
constexpr int kBackgroundMakingSteps = 20;
// The least work (in V-cycles) of a making of the multigrid hierarchy that goes to the
// background: any after the first. Its host work stops a GPU's step of a few milliseconds for
// as long as it takes (the 38k liver's: 8 ms of assembly and 59 of hierarchy here,
// bench/multigrid_making_bench.cpp; bench/RESULTS.md, stop 63), and the hierarchy is made
// seldom (once in about 190 steps there on PoCL), so that 20 more steps on the last one cost
// little.
constexpr double kBackgroundMultigridCycles = 0.0;
inline bool spring_correction_fits(std::size_t spring_rows, int sigma_count) {
  return spring_rows > 0 && spring_rows * static_cast<std::size_t>(sigma_count) <= kSpringRowsTimesSigmaPoints;
}

// DeviceOptions::node_iteration_work's default, measured on lavapipe (bench/RESULTS.md, stop 52).
constexpr long long kNodeIterationWork = 32768;
// llvmpipe (lavapipe's compiler) ends the loops of a shader invocation, silently, once they have
// turned 65535 times in all (gallivm's LP_MAX_TGSI_LOOP_ITERATIONS; bench/RESULTS.md, stop 52):
// the most our Vulkan shaders' loops are planned to turn, with room for those not counted.
constexpr long long kShaderLoopTurns = 61440;
// DeviceOptions::factor_loop_turns' default (kernels/vulkan/factor_solve.comp).
constexpr long long kFactorLoopTurns = kShaderLoopTurns;
// DeviceOptions::lavapipe_serial_work's default, measured on lavapipe on a 2-core machine
// (bench/RESULTS.md, stop 55): serial on the liver (596 tetrahedra) at S = 4 (3.3 against 4.3 ms
// a filter step) and the box (1344) at S = 4 (9.8 against 11.6), threads on the liver at
// S = 16 (6.4 against 7.9 ms a step) and the 4768 liver at S = 4 (20 against 23).
constexpr long long kLavapipeSerialWork = 8192;
// DeviceOptions::cg_sigma_lanes_from's default, measured on lavapipe on a 2-core machine
// (bench/RESULTS.md, stop 57): at S = 16 a sigma point a lane (the 4768 liver's step 21.7 ->
// 19.8 ms, the 596 liver's 5.1 -> 3.9); at S = 4 one a lane would leave four of a vector's 8
// idle and lavapipe's second thread too (the 4768 liver's step 13.3 against 12.3 ms), so there
// J = 8 / S lanes a sigma point instead (vulkan_ensemble.h's cg_lane_rows).
constexpr int kCgSigmaLanesFrom = 16;

struct DeviceOptions {
  int device = 0;                   // index in `sigmafem devices`' list for the back end
  Precision precision = Precision::single;
  SolveLaunch solve_launch = SolveLaunch::automatic;
  KernelForm kernel_form = KernelForm::automatic;
  // Partitions of CG's rows on a GPU, a work-group each for its sigma lanes (OpenCL's GPU form,
  // Vulkan on a GPU; cg_partitions() and cg_groups() in host/ensemble/device_limits.h); 0
  // chooses by the mesh's size.
  int cg_partitions = 0;
  // OpenCL's GPU form and Vulkan's partitioned CG shaders: sigma points side by side in a CG
  // work-group, a power of two (CgGroups, host/ensemble/device_limits.h); 0 chooses (tests and
  // benchmarks compare).
  int cg_sigma_lanes = 0;
  Preconditioner preconditioner = Preconditioner::automatic;
  // OpenCL's CPU form with a factor: each sigma point gets its own (of its own system), from
  // kOwnFactorsFromSigmaPoints, where the S copies of L's values take at most this many
  // bytes, so that they stay in a CPU's cache, and where the sigma points differ by more than
  // the springs a shared factor is corrected for (spring_correction); else one factor of the
  // mean sigma point, shared (0: always shared).
  std::size_t own_factors_bytes = std::size_t{8} << 20;
  // OpenCL's and Vulkan's shared factor corrected for each sigma point's own springs at the
  // estimated ligaments' rows (host/reference/spring_correction.h) where that is small
  // enough; false: the factor alone (tests and benchmarks compare).
  bool spring_correction = true;
  // Vulkan with one CG partition forms q = A d inside its CG iteration shader (two dispatches
  // an iteration instead of three: cg_node_iteration, kernels/vulkan/conjugate_gradient.comp)
  // up to this many element-sigma pairs (elements x S); 0: never (tests compare).
  long long node_iteration_work = kNodeIterationWork;
  // Vulkan with a factor: the loop turns of one factor_solve dispatch (each of L's 4 x 4
  // blocks is one; host/reference/factor_blocks.h), below llvmpipe's limit; tests make it small
  // to cut a solve into many.
  long long factor_loop_turns = kFactorLoopTurns;
  // Vulkan: the most loop turns of one invocation of the CG shaders, whose lanes walk their
  // sigma point's nodes (cg_loop_turns, host/vulkan/vulkan_ensemble.h): where the lanes over
  // sigma points would turn more, a work-group a sigma point (or partition), grown until its
  // lanes turn less; tests make it small.
  long long cg_loop_turns = kShaderLoopTurns;
  // Vulkan on lavapipe: below this many element-sigma pairs (elements x S) its shaders run on
  // the thread that submits them, where handing each dispatch to its threads costs more than
  // they give back (choose_lavapipe_threads, host/vulkan/vulkan_device.h; a user's
  // LP_NUM_THREADS wins); 0: lavapipe's threads always.
  long long lavapipe_serial_work = kLavapipeSerialWork;
  // Vulkan on a CPU device with one CG partition: from this many sigma points the CG shaders
  // take a sigma point a lane, walking its rows alone, where fewer take a work-group a sigma
  // point over its nodes, or at S <= 4 with the factor 8 / S lanes a sigma point
  // (kernels/vulkan/conjugate_gradient.comp, cg_lane_rows); 0: never either (tests compare).
  int cg_sigma_lanes_from = kCgSigmaLanesFrom;
  // Vulkan's CPU form (texel reads) with S a multiple of 4: the element and node shaders take
  // four sigma points a lane (kernels/vulkan/sigma_quads.h); false: one (tests compare).
  bool sigma_quads = true;
  // The shared factor (OpenCL's CPU form, Vulkan on a CPU device) where its making is the work
  // of background_making_solves solves or more, and the multigrid hierarchy at every making
  // after the first: made again in the background and handed over background_making_steps
  // steps later; 0 steps: made at once, the step waiting for it (tests compare).
  int background_making_steps = kBackgroundMakingSteps;
  double background_making_solves = kBackgroundMakingSolves;
  // The V-cycles a making of the multigrid hierarchy counts for in its refresh rule
  // (host/reference/refresh_rule.h); 0: its arithmetic's (NestedMultigrid::setup_in_cycles).
  // Tests make it small, to make the hierarchy again within a few steps.
  double multigrid_making_cycles = 0.0;
  // The device memory a device ensemble may take, in bytes, where less than the device has (a
  // GPU shared with other work; tests); 0: the device's. The memory checks hold the ensemble's
  // buffers to it (usable_device_memory, host/ensemble/device_limits.h).
  std::size_t device_memory = 0;
  // The CPU back end's worker threads: 0, the machine's cores (over MPI ranks, shared among
  // the ranks on one machine: estimation_job.cpp).
  int cpu_threads = 0;
};

}  // namespace sigmafem
