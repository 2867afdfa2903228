// Vulkan's factor solve alone (kernels/vulkan/factor_solve.comp, VulkanFactorSolve): z = M^-1 r
// for S sigma points, all of them iterating, with the springs' correction and CG's finish as
// the ensemble records them (an iteration's direction, no z), `kSolvesASubmit` solves a
// submission. The ensemble's whole step moves 10% between rounds on a shared 2-core machine;
// the solve, a third of it at S = 16, is measured here on fixed data that no CG convergence
// changes (bench/RESULTS.md, stop 61). Float32, device 0 (lavapipe on a CPU-only machine).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "bench_scenarios.h"
#include "host/common/device_options.h"
#include "host/model/model.h"
#include "host/reference/factorised_preconditioner.h"
#include "host/reference/reference_simulation.h"
#include "host/reference/spring_correction.h"
#include "host/vulkan/vulkan_device.h"
#include "host/vulkan/vulkan_factor_solve.h"

namespace sigmafem {
namespace {

constexpr int kSolvesASubmit = 20;

void BM_vulkan_factor_solve(benchmark::State& state, const std::string& mesh, int refinements) {
  const int S = static_cast<int>(state.range(0));
  if (list_vulkan_devices().empty()) {
    state.SkipWithError("no Vulkan device");
    return;
  }
  const Scenario& scenario = bench::scenario(mesh, refinements);
  const Model model = make_model(scenario);
  const Eigen::SparseMatrix<double> A = ReferenceSimulation(model).system_matrix();
  SpringCorrection springs(estimated_spring_rows(model, scenario.filter->estimate));
  FactorisedPreconditioner factor(springs.rows());
  if (!factor.factorise(A)) {
    state.SkipWithError("the system is not positive definite");
    return;
  }
  springs.prepare(factor);
  const int n = static_cast<int>(A.rows());
  const int m = springs.size();

  // Lavapipe's threads as the ensemble takes them: none below kLavapipeSerialWork.
  VulkanDevice device(0, Precision::single,
                      static_cast<long long>(model.element_count()) * S < kLavapipeSerialWork);
  device.set_texel_reads(device.info().type == "cpu");   // the CPU form, as the ensemble's there
  const std::size_t reals = static_cast<std::size_t>(n) * S;
  std::vector<float> r(reals), d(reals);
  for (std::size_t i = 0; i < reals; ++i) {
    r[i] = static_cast<float>(std::sin(0.37 * static_cast<double>(i)));
    d[i] = static_cast<float>(std::cos(0.21 * static_cast<double>(i)));
  }
  const std::vector<std::uint32_t> active(static_cast<std::size_t>(S), 1u);
  const std::vector<float> rz(static_cast<std::size_t>(S), 1.0f);
  VulkanFactorSolve::CgBuffers cg{device.buffer(reals * sizeof(float), "r"), VulkanBuffer{},
                                  device.buffer(reals * sizeof(float), "d"),
                                  device.buffer(active.size() * sizeof(std::uint32_t), "active"),
                                  device.buffer(rz.size() * sizeof(float), "rz")};
  device.upload(cg.r, r.data(), reals * sizeof(float));
  device.upload(cg.active, active.data(), active.size() * sizeof(std::uint32_t));
  VulkanFactorSolve solve(device, n, m, S, cg, DeviceOptions{}.factor_loop_turns);
  solve.upload(factor);
  if (!solve.upload_springs(springs)) {
    state.SkipWithError("the springs' correction does not fit a dispatch");
    return;
  }
  // Each sigma point's coupling: a stiffness change of 5% to 15% at its springs' rows.
  std::vector<double> couplings;
  for (int s = 0; s < S; ++s) {
    Eigen::VectorXd delta(m);
    for (int j = 0; j < m; ++j) delta[j] = 0.05 * (1.0 + 0.1 * ((s + j) % 3)) * A.coeff(springs.rows()[j], springs.rows()[j]);
    const Eigen::MatrixXd H = springs.coupling(delta);
    for (int j = 0; j < m; ++j)
      for (int k = 0; k < m; ++k) couplings.push_back(H(j, k));
  }
  VkCommandBuffer cmd = device.begin();
  solve.record_couplings(cmd, couplings);
  device.barrier(cmd);
  device.submit_and_wait(cmd);

  // r stays, so from the second solve on the finish's beta is r.z / r.z = 1: d = z + d grows
  // by z a solve, far from float32's range in any run.
  device.upload(cg.d, d.data(), reals * sizeof(float));
  device.upload(cg.rz, rz.data(), rz.size() * sizeof(float));
  for (auto _ : state) {
    cmd = device.begin();
    for (int i = 0; i < kSolvesASubmit; ++i) solve.record(cmd, SF_FACTOR_FINISH_DIRECTION);
    device.submit_and_wait(cmd);
  }
  state.counters["S"] = S;
  state.counters["rows"] = n;
  state.counters["nonzeros"] = static_cast<double>(factor.nonzeros());
  state.counters["dispatches_a_solve"] = solve.dispatches();
  // Microseconds a solve: the inverse of a rate of solves a microsecond.
  state.counters["us_a_solve"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * kSolvesASubmit * 1e-6,
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.SetLabel(std::string(solve.shared() ? "shared" : "split ") + " " + device.info().name);
}

BENCHMARK_CAPTURE(BM_vulkan_factor_solve, liver_596, std::string("liver"), 0)
    ->Arg(4)->Arg(16)->Unit(benchmark::kMicrosecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_vulkan_factor_solve, liver_4768, std::string("liver"), 1)
    ->Arg(4)->Arg(16)->Unit(benchmark::kMicrosecond)->UseRealTime();

}  // namespace
}  // namespace sigmafem
