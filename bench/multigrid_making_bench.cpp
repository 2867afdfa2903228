// The host's work of one making of the multigrid hierarchy (host/reference/nested_multigrid.h),
// the GPU forms' preconditioner on refined meshes: the assembly of the representative's
// implicit-Euler matrix and the hierarchy made of it (Galerkin products, the smoothing's
// spectra, the coarsest level's inverse). Made at once, this is what stopped the step it fell
// in; since stop 63 every making after the first runs on a host thread (BackgroundMaking).
// Both at rest, on the three refined meshes of the GPU benchmarks. Results: bench/RESULTS.md.
#include <benchmark/benchmark.h>

#include <string>

#include "bench/bench_scenarios.h"
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

BENCHMARK_CAPTURE(BM_representative_assembly, liver_4768, std::string("liver"), 1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_representative_assembly, liver_fine_38144, std::string("liver_fine"), 0)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_representative_assembly, box_large_117240, std::string("box_large"), 0)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_multigrid_making, liver_4768, std::string("liver"), 1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_multigrid_making, liver_fine_38144, std::string("liver_fine"), 0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_multigrid_making, box_large_117240, std::string("box_large"), 0)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace sigmafem
