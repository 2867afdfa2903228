// Speed of the CPU reference (ARCHITECTURE.md, "Measuring speed"): one implicit Euler step on
// the shipped scenarios and on the box refined once (about 10k tetrahedra), and the bare
// element product that every CG iteration repeats. The unit is the element-iteration: one
// element's matrix-free product in one CG iteration. Results: bench/RESULTS.md.
#include <benchmark/benchmark.h>

#include <string>

#include "bench/bench_scenarios.h"
#include "host/model/model.h"
#include "host/reference/corotational.h"
#include "host/reference/reference_simulation.h"
#include "host/scenario/scenario.h"

namespace sigmafem {
namespace {

using bench::scenario;

// Warmed-up simulation: 20 steps in, so that the organ is deformed and CG warm-starts.
ReferenceSimulation warmed_up(const Scenario& s, int& step) {
  ReferenceSimulation simulation(make_model(s));
  for (step = 1; step <= 20; ++step)
    simulation.step(bench::so_position(s, step));
  return simulation;
}

void BM_reference_step(benchmark::State& state, const std::string& name, int refinements) {
  const Scenario& s = scenario(name, refinements);
  int step = 0;
  ReferenceSimulation simulation = warmed_up(s, step);
  long long iterations = 0;
  for (auto _ : state) {
    const CgResult cg =
        simulation.step(bench::so_position(s, step));
    iterations += cg.iterations;
    ++step;
  }
  const double elements = s.mesh.tetrahedron_count();
  state.counters["tetrahedra"] = elements;
  state.counters["cg_iterations_per_step"] =
      static_cast<double>(iterations) / static_cast<double>(state.iterations());
  state.counters["element_iterations_per_s"] =
      benchmark::Counter(elements * static_cast<double>(iterations), benchmark::Counter::kIsRate);
  state.counters["sigma_point_steps_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.SetLabel("cpu-reference double, 1 thread");
}

void BM_element_product(benchmark::State& state, const std::string& name, int refinements) {
  const Scenario& s = scenario(name, refinements);
  int step = 0;
  ReferenceSimulation simulation = warmed_up(s, step);
  const Model& model = simulation.model();
  std::vector<Frame> frames;
  element_frames(model, simulation.positions(), frames);
  const Eigen::VectorXd d = simulation.velocities();
  Eigen::VectorXd y;
  for (auto _ : state) {
    element_product(model, frames, d, y);
    benchmark::DoNotOptimize(y.data());
  }
  state.counters["tetrahedra"] = s.mesh.tetrahedron_count();
  state.counters["element_iterations_per_s"] = benchmark::Counter(
      static_cast<double>(s.mesh.tetrahedron_count()), benchmark::Counter::kIsIterationInvariantRate);
  state.SetLabel("cpu-reference double, 1 thread");
}

BENCHMARK_CAPTURE(BM_reference_step, liver_596, std::string("liver"), 0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_reference_step, box, std::string("box"), 0)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_reference_step, box_refined_10k, std::string("box"), 1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_element_product, liver_596, std::string("liver"), 0)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_element_product, box, std::string("box"), 0)->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_element_product, box_refined_10k, std::string("box"), 1)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace sigmafem
