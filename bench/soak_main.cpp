// sigmafem_soak: the soak run of issue 14. Runs the filter of a scenario on its data for as
// many steps as the data has, on a device back end, and samples the process's resident memory
// (VmRSS) every EVERY steps. The run keeps only the change detection's window of steps
// (EstimationOptions::keep_all_steps false), as an unbounded run must: what grows then is a
// leak (device buffers, per-step allocations), and memory must stay within 5% of its level
// at step 1000.
//   sigmafem_soak SCENARIO DATA_DIR [BACKEND [EVERY]]     (defaults: opencl, 1000)
// Prints `step,rss_kb` rows on stdout and a summary on stderr; exit 1 if memory grew by more
// than 5%, 2 on bad use. bench/soak_liver.sh makes the data and runs it on the liver.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iostream>
#include <string>

#include "filter/estimation.h"
#include "host/data/observation_table.h"
#include "host/engine/estimation_options.h"
#include "host/engine/make_ensemble.h"
#include "host/model/model.h"
#include "host/scenario/scenario.h"

namespace {

long resident_kb() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * (sysconf(_SC_PAGESIZE) / 1024);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace sigmafem;
  if (argc < 3 || argc > 5) {
    std::cerr << "usage: sigmafem_soak SCENARIO DATA_DIR [BACKEND [EVERY]]\n";
    return 2;
  }
  const std::string backend = argc > 3 ? argv[3] : "opencl";
  const int every = argc > 4 ? std::max(1, std::atoi(argv[4])) : 1000;
  try {
    const Scenario scenario = load_scenario(argv[1]);
    if (!scenario.filter) throw std::runtime_error(std::string(argv[1]) + ": no filter block");
    const ObservationTable data =
        read_observations_csv(std::string(argv[2]) + "/observations.csv",
                              static_cast<int>(scenario.observations.observed.size()), scenario.time.dt);
    EstimationOptions options = estimation_options(scenario);
    options.keep_all_steps = false;
    const int sigma_count =
        sigma_point_count(options.roukf.sigma_points, static_cast<int>(scenario.filter->estimate.size()));
    auto ensemble = make_ensemble(backend, make_model(scenario), scenario.filter->estimate,
                                  scenario.observations.observed, sigma_count);
    std::cout << "step,rss_kb\n";
    long at_1000 = 0, highest = 0, highest_step = 0;
    const EstimationRun run =
        run_estimation(*ensemble, options, data.times, data.so, data.points, [&](const EstimationStep& step) {
          if (step.step % every != 0) return;
          const long rss = resident_kb();
          std::cout << step.step << ',' << rss << '\n' << std::flush;
          if (step.step < 1000) return;
          if (at_1000 == 0) at_1000 = rss;
          if (rss > highest) {
            highest = rss;
            highest_step = step.step;
          }
        });
    if (!run.complete) throw std::runtime_error("the filter stopped: " + run.stop_reason);
    const int steps = run.steps.empty() ? 0 : run.steps.back().step;
    if (at_1000 == 0) throw std::runtime_error("fewer than 1000 steps: nothing to compare");
    const double growth = static_cast<double>(highest - at_1000) / static_cast<double>(at_1000);
    std::fprintf(stderr,
                 "%s on %s: %d filter steps; VmRSS at step 1000 %ld kB, highest after it %ld kB (step %ld): "
                 "%+.2f%% (limit 5%%)\n",
                 scenario.name.c_str(), backend.c_str(), steps, at_1000, highest, highest_step,
                 100.0 * growth);
    return growth > 0.05 ? 1 : 0;
  } catch (const std::exception& e) {
    std::cerr << "sigmafem_soak: " << e.what() << '\n';
    return 2;
  }
}
