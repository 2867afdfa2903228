// The ROUKF re-sampling of the sigma states (filter/ensemble.h resampled_states), what rank 0
// of an MPI run does for all S each filter step (host/mpi/) and the CPU back end for its own:
// the formula on the whole matrix on one thread, against host/ensemble/threaded_resampling.h's
// blocks of rows on 1 and 2 threads. The 38k liver's state: 3 x 8 000-odd node coordinates
// (n = 24 000), its positions and velocities, star sigma points at p = 64 (S = 129).
#include <benchmark/benchmark.h>

#include <random>

#include "host/ensemble/threaded_resampling.h"

namespace sigmafem {
namespace {

constexpr Eigen::Index kStateSize = 24000;
constexpr Eigen::Index kParameters = 64;
constexpr Eigen::Index kSigmaPoints = 2 * kParameters + 1;

struct Problem {
  Recentering recentering;
  Eigen::MatrixXd X, V;
};

const Problem& problem() {
  static const Problem p = [] {
    Problem made;
    std::mt19937 random(7);
    std::normal_distribution<double> normal;
    auto fill = [&](Eigen::Index rows, Eigen::Index cols) {
      Eigen::MatrixXd m(rows, cols);
      for (Eigen::Index j = 0; j < cols; ++j)
        for (Eigen::Index i = 0; i < rows; ++i) m(i, j) = normal(random);
      return m;
    };
    made.recentering.alpha = 1.0 / static_cast<double>(kSigmaPoints);
    made.recentering.directions = fill(kParameters, kSigmaPoints);
    made.recentering.correction = fill(kParameters, 1);
    made.recentering.factor = fill(kParameters, kParameters);
    made.X = fill(kStateSize, kSigmaPoints);
    made.V = fill(kStateSize, kSigmaPoints);
    return made;
  }();
  return p;
}

void count(benchmark::State& state) {
  state.counters["n"] = static_cast<double>(kStateSize);
  state.counters["S"] = static_cast<double>(kSigmaPoints);
  state.counters["p"] = static_cast<double>(kParameters);
}

void BM_resampling_whole(benchmark::State& state) {
  const Problem& p = problem();
  for (auto _ : state) {
    benchmark::DoNotOptimize(resampled_states(p.X, p.recentering));
    benchmark::DoNotOptimize(resampled_states(p.V, p.recentering));
  }
  count(state);
}
BENCHMARK(BM_resampling_whole)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_resampling_blocks(benchmark::State& state) {
  const Problem& p = problem();
  WorkerPool pool(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    benchmark::DoNotOptimize(resampled_states_on(pool, p.X, p.recentering));
    benchmark::DoNotOptimize(resampled_states_on(pool, p.V, p.recentering));
  }
  count(state);
  state.counters["threads"] = static_cast<double>(state.range(0));
}
BENCHMARK(BM_resampling_blocks)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace sigmafem
