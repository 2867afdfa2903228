// liver.json on its mesh refined `refine` times (refine_uniform keeps the file's nodes and
// their indices, so its node lists stay valid): a mesh with multigrid levels, for the tests of
// the V-cycle (host/reference/nested_multigrid.h) and of the ensembles that use it; and what
// those ensembles' tests run on it.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <string>

#include "host/common/device_error.h"
#include "host/ensemble/device_ensemble.h"
#include "host/ensemble/device_limits.h"
#include "host/scenario/scenario.h"
#include "tests/scenario_directory.h"

namespace sigmafem::test {

inline Scenario refined_liver(int refine) {
  Scenario scenario = load_scenario(kScenarios + "liver.json");
  for (int level = 0; level < refine; ++level) scenario.mesh = refine_uniform(scenario.mesh);
  return scenario;
}

// Each sigma point's log-stiffnesses, the scenario's spread by up to `spread`.
inline Eigen::MatrixXd spread_log_stiffness(const Scenario& scenario, const Model& model, int S, double spread) {
  const std::vector<int>& estimated = scenario.filter->estimate;
  Eigen::MatrixXd theta(static_cast<Eigen::Index>(estimated.size()), S);
  for (Eigen::Index j = 0; j < theta.rows(); ++j)
    for (int s = 0; s < S; ++s)
      theta(j, s) = std::log(model.ligaments[static_cast<std::size_t>(estimated[static_cast<std::size_t>(j)])].stiffness) +
                    spread * std::sin(static_cast<double>(s + j));
  return theta;
}

// `steps` steps of the scenario's motion with parameters `theta`, every sigma point converging;
// each step's CG iterations added to `iterations`. Returns the positions, 3N x S.
inline Eigen::MatrixXd run_steps(SimulationEnsemble& ensemble, const Scenario& scenario, const Eigen::MatrixXd& theta,
                                 int steps, long& iterations) {
  ensemble.set_parameters(theta);
  const int S = ensemble.sigma_count();
  for (int step = 1; step <= steps; ++step) {
    const StepReport report =
        ensemble.advance(scenario.control.trajectory.position(step * scenario.time.dt, scenario.control.start));
    for (int s = 0; s < S; ++s) {
      EXPECT_TRUE(report.converged[s]) << "step " << step << ", sigma point " << s;
      iterations += report.cg_iterations[s];
    }
  }
  Eigen::MatrixXd x, v;
  ensemble.read_states(x, v);
  return x;
}

// The memory check of an ensemble's multigrid hierarchy (check_more_device_memory), made at the
// first step, when its matrices are known: `Ensemble` with `options` (the V-cycle) capped by
// DeviceOptions::device_memory with room for its own buffers but for only half the hierarchy's
// refuses its first step with "out of device memory" naming the multigrid levels; capped at
// what it holds with them, it steps.
template <class Ensemble>
void expect_multigrid_memory_checked(const Scenario& scenario, const Model& model, int S, DeviceOptions options) {
  const Eigen::Vector3d so = scenario.control.trajectory.position(scenario.time.dt, scenario.control.start);
  const auto make = [&] { return Ensemble(model, scenario.filter->estimate, scenario.observations.observed, S, options); };
  std::size_t own = 0, with_levels = 0;
  {
    Ensemble uncapped = make();
    ASSERT_TRUE(uncapped.multigrid());
    own = uncapped.device_bytes();
    uncapped.advance(so);
    with_levels = uncapped.device_bytes();
  }
  const std::size_t levels = with_levels - own;
  // The construction's own check is of an estimate (ensemble_memory): the cap must pass it.
  const std::size_t estimate =
      ensemble_memory(model.node_count(), model.element_count(), S, real_size(options.precision)).total;
  ASSERT_LT(estimate, own + levels / 2) << "no cap between the ensemble's estimate and its hierarchy";
  options.device_memory = own + levels / 2;
  Ensemble capped = make();
  try {
    capped.advance(so);
    ADD_FAILURE() << "expected the multigrid levels to be refused";
  } catch (const DeviceError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("out of device memory: the multigrid levels"), std::string::npos) << message;
    EXPECT_NE(message.find("MiB"), std::string::npos) << message;
  }
  options.device_memory = with_levels;
  Ensemble enough = make();
  EXPECT_EQ(enough.advance(so).unconverged_count(), 0);
  EXPECT_EQ(enough.device_bytes(), with_levels);
}

}  // namespace sigmafem::test
