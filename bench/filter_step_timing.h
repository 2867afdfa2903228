// time_filter_steps: whole ROUKF filter steps timed on any ensemble, for the benchmark
// programs (sigmafem_bench, and sigmafem_mpi_bench over MPI ranks). Header-only: every bench
// source is its own translation unit.
#pragma once

#include <benchmark/benchmark.h>

#include "bench/bench_scenarios.h"
#include "filter/roukf.h"
#include "host/model/model.h"
#include "host/reference/reference_simulation.h"

namespace sigmafem::bench {

// Times whole filter steps of `ensemble` on `s`: re-centre, advance, gather, correct (the
// truth, `model` simulated beside it outside the timing, gives the observations).
inline void time_filter_steps(benchmark::State& state, Ensemble& ensemble, const Scenario& s, const Model& model,
                              RoukfOptions options, SigmaPointSet set = SigmaPointSet::simplex) {
  options.sigma_points = set;
  Roukf filter(options, ensemble);
  ReferenceSimulation truth(model);
  Eigen::VectorXd y(3 * static_cast<Eigen::Index>(s.observations.observed.size()));
  int step = 0;
  const auto observe = [&] {
    ++step;
    const Eigen::Vector3d so = so_position(s, step);
    truth.step(so);
    for (std::size_t k = 0; k < s.observations.observed.size(); ++k)
      y.segment<3>(3 * static_cast<Eigen::Index>(k)) = s.observations.observed[k].of(truth.positions());
    return so;
  };
  // Warm-up steps, untimed: PoCL compiles a kernel at its first launch.
  for (int i = 0; i < 5; ++i) {
    const Eigen::Vector3d so = observe();
    filter.step(so, y);
  }
  // The factorisations in the timed steps (CPU back end, OpenCL's shared factor; issue 18),
  // as the steps' reports give them.
  int factorisations = 0;
  double cg_iterations = 0.0;   // summed over the sigma points and the steps
  for (auto _ : state) {
    state.PauseTiming();
    const Eigen::Vector3d so = observe();
    state.ResumeTiming();
    const RoukfStep result = filter.step(so, y);
    factorisations += result.ensemble.factorisations;
    for (int n : result.ensemble.cg_iterations) cg_iterations += n;
    benchmark::DoNotOptimize(result);
  }
  const double steps = static_cast<double>(state.iterations());
  state.counters["factorisations_per_step"] = factorisations / steps;
  state.counters["cg_iterations"] = cg_iterations / (steps * ensemble.sigma_count());
  state.counters["sigma_points"] = ensemble.sigma_count();
  state.counters["parameters"] = ensemble.parameter_count();
  state.counters["tetrahedra"] = model.element_count();
}

}  // namespace sigmafem::bench
