// liver.json on its mesh refined `refine` times (refine_uniform keeps the file's nodes and
// their indices, so its node lists stay valid): a mesh with multigrid levels, for the tests of
// the V-cycle (host/reference/nested_multigrid.h) and of the ensembles that use it; and what
// those ensembles' tests run on it.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cmath>

#include "host/ensemble/device_ensemble.h"
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

}  // namespace sigmafem::test
