// generated_observations: what `generate` writes for a scenario (no VTK frames), read back as
// the filter takes it; the temporary folder is removed. Header-only: tests compile
// *_test.cpp only.
#pragma once

#include <filesystem>
#include <sstream>
#include <string>

#include "temp_path.h"
#include "host/data/observation_table.h"
#include "host/generator/generate.h"
#include "host/scenario/scenario.h"

namespace sigmafem::test {

inline ObservationTable generated_observations(const Scenario& scenario, GenerateOptions options = {}) {
  const std::filesystem::path dir = unique_temp_path("sigmafem_generated_data");
  options.out_dir = dir.string();
  options.vtk_every = 0;
  std::ostringstream log;
  generate(scenario, options, log);
  ObservationTable table = read_observations_csv((dir / "observations.csv").string(),
                                                 static_cast<int>(scenario.observations.nodes.size()),
                                                 scenario.time.dt);
  std::filesystem::remove_all(dir);
  return table;
}

}  // namespace sigmafem::test
