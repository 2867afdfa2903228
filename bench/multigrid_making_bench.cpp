// The host's work of one making of the multigrid hierarchy (host/reference/nested_multigrid.h),
// the GPU forms' preconditioner on refined meshes: the assembly of the representative's
// implicit-Euler matrix and the hierarchy made of it (Galerkin products, the smoothing's
// spectra, the coarsest level's inverse). Made at once, this is what stopped the step it fell
// in; since stop 63 every making after the first runs on a host thread (BackgroundMaking).
// Both at rest, on the three refined meshes of the GPU benchmarks; and the slowest step of a
// device ensemble that makes the hierarchy often, at once or in the background. Results:
// bench/RESULTS.md.
#include <benchmark/benchmark.h>

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <memory>
#include <string>

#include "bench/bench_scenarios.h"
#include "host/engine/make_ensemble.h"
#include "host/model/model.h"
#include "host/reference/nested_multigrid.h"
#include "host/reference/reference_simulation.h"
#include "host/scenario/scenario.h"

namespace sigmafem {
namespace {

// The representative's matrix assembled (ReferenceSimulation::system_matrix, as
// DeviceEnsemble::system_at makes it), after the first assembly, which finds the pattern that
// later ones fill.
void BM_representative_assembly(benchmark::State& state, const std::string& name, int refinements) {
  const ReferenceSimulation simulation(make_model(bench::scenario(name, refinements)));
  benchmark::DoNotOptimize(simulation.system_matrix());
  for (auto _ : state) benchmark::DoNotOptimize(simulation.system_matrix());
  state.counters["tetrahedra"] = bench::scenario(name, refinements).mesh.tetrahedron_count();
}

// The hierarchy made of that matrix (NestedMultigrid::set_matrix).
void BM_multigrid_making(benchmark::State& state, const std::string& name, int refinements) {
  const Model model = make_model(bench::scenario(name, refinements));
  const Eigen::SparseMatrix<double> A = ReferenceSimulation(model).system_matrix();
  NestedMultigrid multigrid(nested_prolongations(model));
  for (auto _ : state)
    if (!multigrid.set_matrix(A)) state.SkipWithError("the matrix is not positive definite");
  state.counters["tetrahedra"] = model.element_count();
  state.counters["levels"] = multigrid.level_count();
  state.counters["setup_in_cycles"] = multigrid.setup_in_cycles();
}

// A device ensemble's steps (S = 4, the GPU form, the V-cycle) with the hierarchy made again
// whenever a step takes more CG iterations than the first after the last making (its making
// counted as one V-cycle: DeviceOptions::multigrid_making_cycles), which every tenth step's
// change of the stiffnesses (by e^0.5 one way, then back) brings about, made at once (`lag` 0)
// or in the background, handed over `lag` steps later: the slowest step against the mean, what
// a making costs a real-time step. Meant for a GPU (bench/gpu_checks.sh); on PoCL the GPU form
// is forced and a step is long beside a making.
void BM_steps_with_makings(benchmark::State& state, const std::string& backend, const std::string& name,
                           int refinements, int lag) {
  const Scenario& s = bench::scenario(name, refinements);
  const Model model = make_model(s);
  const int S = 4;
  DeviceOptions options;
  options.kernel_form = KernelForm::gpu;
  options.preconditioner = Preconditioner::multigrid;
  options.multigrid_making_cycles = 1.0;
  options.background_making_steps = lag;
  std::unique_ptr<SimulationEnsemble> ensemble;
  try {
    ensemble = make_ensemble(backend, model, s.filter->estimate, s.observations.observed, S, options);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  Eigen::MatrixXd theta(ensemble->parameter_count(), S);
  for (Eigen::Index j = 0; j < theta.rows(); ++j)
    for (int k = 0; k < S; ++k)
      theta(j, k) = std::log(model.ligaments[s.filter->estimate[j]].stiffness) + 0.3 * std::sin(k + j);
  ensemble->set_parameters(theta);
  int step = 1;
  for (; step <= 5; ++step) ensemble->advance(bench::so_position(s, step));   // the first making
  double slowest = 0.0;
  int makings = 0;
  for (auto _ : state) {
    if (step % 10 == 0) ensemble->set_parameters(Eigen::MatrixXd(theta.array() + (step % 20 == 0 ? 0.0 : 0.5)));
    const auto start = std::chrono::steady_clock::now();
    makings += ensemble->advance(bench::so_position(s, step++)).factorisations;
    slowest = std::max(slowest, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  state.counters["slowest_step_ms"] = slowest;
  state.counters["makings"] = makings;
  state.SetLabel(backend + (lag > 0 ? ", in the background" : ", at once"));
}

BENCHMARK_CAPTURE(BM_representative_assembly, liver_4768, std::string("liver"), 1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_representative_assembly, liver_fine_38144, std::string("liver_fine"), 0)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_representative_assembly, box_large_117240, std::string("box_large"), 0)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_multigrid_making, liver_4768, std::string("liver"), 1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_multigrid_making, liver_fine_38144, std::string("liver_fine"), 0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_multigrid_making, box_large_117240, std::string("box_large"), 0)->Unit(benchmark::kMillisecond);
// 100 steps: a making every few of them.
BENCHMARK_CAPTURE(BM_steps_with_makings, opencl_at_once_liver_fine_38144, std::string("opencl"),
                  std::string("liver_fine"), 0, 0)->Iterations(100)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_steps_with_makings, opencl_background_liver_fine_38144, std::string("opencl"),
                  std::string("liver_fine"), 0, kBackgroundMakingSteps)
    ->Iterations(100)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_steps_with_makings, vulkan_at_once_liver_fine_38144, std::string("vulkan"),
                  std::string("liver_fine"), 0, 0)->Iterations(100)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_steps_with_makings, vulkan_background_liver_fine_38144, std::string("vulkan"),
                  std::string("liver_fine"), 0, kBackgroundMakingSteps)
    ->Iterations(100)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_steps_with_makings, opencl_at_once_liver_4768, std::string("opencl"), std::string("liver"), 1, 0)
    ->Iterations(100)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_steps_with_makings, opencl_background_liver_4768, std::string("opencl"), std::string("liver"), 1,
                  kBackgroundMakingSteps)->Iterations(100)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace sigmafem
