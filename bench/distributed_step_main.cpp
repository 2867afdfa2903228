// sigmafem_mpi_bench: whole filter steps with the sigma points over MPI ranks (issue 19:
// strong scaling), on the liver or the 38k liver with p - 3 region moduli beside the 3
// ligaments (S = p + 1 simplex, 2p + 1 star). One case per run, since the ranks are mpirun's:
//   mpirun -n R build/bench/sigmafem_mpi_bench [--mesh liver|liver_fine] [--parameters P]
//        [--backend cpu|opencl|vulkan] [--sigma simplex|star] [--steps N] [Google Benchmark flags]
// Rank 0 times the steps (BM_distributed_filter_step/<mesh>/p:<P>/<backend>/ranks:<R>); the
// other ranks serve their shares. Results: bench/RESULTS.md.
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <iostream>
#include <memory>
#include <string>

#include "bench/bench_scenarios.h"
#include "bench/filter_step_timing.h"
#include "host/engine/estimation_options.h"
#include "host/engine/make_ensemble.h"
#include "host/model/estimated_parameters.h"
#include "host/mpi/distributed_ensemble.h"
#include "host/mpi/ranks.h"

namespace {

struct Case {
  std::string mesh = "liver";
  int parameters = 16;
  std::string backend = "cpu";
  std::string sigma = "simplex";
  int steps = 20;
};

// Takes this program's own options out of argv (Google Benchmark reads the rest).
Case take_options(int& argc, char** argv) {
  Case c;
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    const bool has_value = i + 1 < argc;
    if (flag == "--mesh" && has_value) c.mesh = argv[++i];
    else if (flag == "--parameters" && has_value) c.parameters = std::atoi(argv[++i]);
    else if (flag == "--backend" && has_value) c.backend = argv[++i];
    else if (flag == "--steps" && has_value) c.steps = std::atoi(argv[++i]);
    else if (flag == "--sigma" && has_value) c.sigma = argv[++i];
    else argv[kept++] = argv[i];
  }
  argc = kept;
  return c;
}

int run(int argc, char** argv) {
  using namespace sigmafem;
  const Case c = take_options(argc, argv);
  if ((c.mesh != "liver" && c.mesh != "liver_fine") || c.parameters < 4 || c.parameters > 64 || c.steps < 1 ||
      (c.sigma != "simplex" && c.sigma != "star"))
    throw std::invalid_argument("--mesh liver|liver_fine, --parameters 4 to 64, --sigma simplex|star, --steps 1 or more");
  const RankInfo& world = ranks();
  const SigmaPointSet set = parse_sigma_point_set(c.sigma);
  const int S = sigma_point_count(set, c.parameters);
  if (world.size > S) throw std::invalid_argument("more ranks than sigma points");
  const Scenario s = bench::with_region_moduli(bench::scenario(c.mesh, 0), c.parameters);
  Model model = make_model(s);
  const EstimatedParameters estimated = estimated_parameters(*s.filter, model);
  DeviceOptions options;
  options.cpu_threads = world.cores_per_rank();
  std::unique_ptr<SimulationEnsemble> local = make_share(S, [&](int count) {
    return make_ensemble(c.backend, model, estimated, s.observations.observed, count, options);
  });
  if (world.rank != 0) {
    serve_ensemble(*local, S);
    return 0;
  }
  DistributedEnsemble ensemble(std::move(local), S);
  const std::string name = "BM_distributed_filter_step/" + c.mesh + "/p:" + std::to_string(c.parameters) + "/" +
                           c.sigma + "/" + c.backend + "/ranks:" + std::to_string(world.size);
  benchmark::RegisterBenchmark(name.c_str(), [&](benchmark::State& state) {
    const double before = ensemble.recenter_seconds();
    bench::time_filter_steps(state, ensemble, s, model, estimation_options(s).roukf, set);
    // The re-centrings of the warm-up steps count too: per step over all of them.
    state.counters["recenter_ms"] = 1e3 * (ensemble.recenter_seconds() - before) / (static_cast<double>(state.iterations()) + 5.0);
    state.counters["ranks"] = world.size;
    state.counters["threads_per_rank"] = options.cpu_threads;
  })->Iterations(c.steps)->Unit(benchmark::kMillisecond)->UseRealTime();
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  int code = 0;
  try {
    sigmafem::start_ranks(&argc, &argv);
    code = run(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << sigmafem::program_name() << ": " << e.what() << '\n';
    code = 1;
  }
  sigmafem::finish_ranks();
  return code;
}
