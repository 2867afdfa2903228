// OpenCL's shared factor (OpenClEnsemble, kernels/opencl/conjugate_gradient.cl SF_FACTOR; the
// default on a CPU device): CG is preconditioned by one sparse Cholesky factor of the mean
// sigma point's system, made on the host and shared by all sigma points. The trajectories
// follow the CPU back end's as Jacobi's do, in a fraction of Jacobi's iterations, in both of
// the CPU form's launches (the whole solve in one, an iteration per launch), fewer again with
// its correction for each sigma point's springs; without a factor the diagonal stands in; the
// GPU form refuses it.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "host/ensemble/cpu_ensemble.h"
#include "host/model/model.h"
#include "host/opencl/opencl_device.h"
#include "host/opencl/opencl_ensemble.h"
#include "host/scenario/scenario.h"
#include "background_making_runs.h"
#include "requirement.h"

namespace sigmafem {
namespace {

// float32 against double, each CG stopping within its tolerance (1e-6 relative in float32),
// each from its own preconditioner: over 40 steps of the liver the positions differ from the
// CPU back end's by up to 7.1e-8 m with Jacobi and 7.0e-8 m with the factor (measured; the
// organ moves by centimetres). 1e-6 m leaves a factor of 14.
constexpr double kPositionTolerance = 1e-6;
constexpr int kSteps = 40;
constexpr int kSigmaPoints = 4;

class OpenClFactorTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (list_opencl_devices().empty()) SIGMAFEM_MISSING("no OpenCL platform on this machine");
    scenario_ = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/liver.json");
    model_ = make_model(scenario_);
    const std::vector<int>& estimated = scenario_.filter->estimate;
    theta_.resize(static_cast<Eigen::Index>(estimated.size()), kSigmaPoints);
    for (Eigen::Index j = 0; j < theta_.rows(); ++j)
      for (int s = 0; s < kSigmaPoints; ++s)
        theta_(j, s) = std::log(model_.ligaments[estimated[static_cast<std::size_t>(j)]].stiffness) +
                       0.3 * std::sin(static_cast<double>(s + j));
  }
  // Runs `steps` steps (kSteps unless given); returns the positions of every sigma point (3N x S) and adds each
  // step's largest CG iteration count to `iterations`.
  Eigen::MatrixXd run(SimulationEnsemble& ensemble, long& iterations, int steps = kSteps) const {
    ensemble.set_parameters(theta_);
    for (int step = 1; step <= steps; ++step) {
      const StepReport report = ensemble.advance(
          scenario_.control.trajectory.position(step * scenario_.time.dt, scenario_.control.start));
      for (int s = 0; s < kSigmaPoints; ++s) {
        EXPECT_TRUE(report.converged[s]) << "step " << step << ", sigma point " << s;
        iterations += report.cg_iterations[s];
      }
    }
    Eigen::MatrixXd x(model_.dof_count(), kSigmaPoints);
    for (int s = 0; s < kSigmaPoints; ++s) {
      if (auto* device = dynamic_cast<DeviceEnsemble*>(&ensemble))
        x.col(s) = device->positions(s);
      else
        x.col(s) = dynamic_cast<CpuEnsemble&>(ensemble).simulation(s).positions();
    }
    return x;
  }
  OpenClEnsemble opencl(Preconditioner preconditioner, SolveLaunch launch,
                        bool spring_correction = true) const {
    DeviceOptions options;
    options.spring_correction = spring_correction;
    options.kernel_form = KernelForm::cpu;
    options.preconditioner = preconditioner;
    options.solve_launch = launch;
    return OpenClEnsemble(model_, scenario_.filter->estimate, scenario_.observations.observed,
                          kSigmaPoints, options);
  }
  Scenario scenario_;
  Model model_;
  Eigen::MatrixXd theta_;
};

TEST_F(OpenClFactorTest, FollowsTheCpuBackEndInAFractionOfJacobisIterations) {
  CpuEnsemble cpu(model_, scenario_.filter->estimate, scenario_.observations.observed, kSigmaPoints);
  long cpu_iterations = 0;
  const Eigen::MatrixXd expected = run(cpu, cpu_iterations);
  for (SolveLaunch launch : {SolveLaunch::whole_solve, SolveLaunch::per_iteration}) {
    const char* name = launch == SolveLaunch::whole_solve ? "whole solve" : "per iteration";
    long jacobi_iterations = 0, factor_iterations = 0;
    OpenClEnsemble jacobi = opencl(Preconditioner::jacobi, launch);
    const Eigen::MatrixXd with_jacobi = run(jacobi, jacobi_iterations);
    OpenClEnsemble factor = opencl(Preconditioner::factorised, launch);
    const Eigen::MatrixXd with_factor = run(factor, factor_iterations);
    const double jacobi_error = (with_jacobi - expected).cwiseAbs().maxCoeff();
    const double factor_error = (with_factor - expected).cwiseAbs().maxCoeff();
    EXPECT_LE(jacobi_error, kPositionTolerance) << name << ": Jacobi against the CPU back end";
    EXPECT_LE(factor_error, kPositionTolerance) << name << ": the factor against the CPU back end";
    EXPECT_LE(5 * factor_iterations, jacobi_iterations)
        << name << ": " << factor_iterations << " iterations with the factor, " << jacobi_iterations
        << " with Jacobi (" << cpu_iterations << " on the CPU back end's own factors)";
    std::cout << name << ": largest difference from the CPU back end " << jacobi_error
              << " m with Jacobi, " << factor_error << " m with the factor; iterations "
              << jacobi_iterations << " and " << factor_iterations << "\n";
  }
}

// The shared factor corrected for each sigma point's own springs (SpringCorrection, the
// default) against the factor alone: the same trajectories, in fewer iterations, in both
// launches. The sigma points here spread by +-0.3 in log-stiffness (the filter's start, by
// its initial_log_std of 1, spreads them by up to 1.7).
TEST_F(OpenClFactorTest, TheSpringCorrectionSavesIterations) {
  for (SolveLaunch launch : {SolveLaunch::whole_solve, SolveLaunch::per_iteration}) {
    const char* name = launch == SolveLaunch::whole_solve ? "whole solve" : "per iteration";
    long alone_iterations = 0, corrected_iterations = 0;
    OpenClEnsemble alone = opencl(Preconditioner::factorised, launch, false);
    const Eigen::MatrixXd without = run(alone, alone_iterations);
    OpenClEnsemble corrected = opencl(Preconditioner::factorised, launch);
    const Eigen::MatrixXd with = run(corrected, corrected_iterations);
    EXPECT_LE((with - without).cwiseAbs().maxCoeff(), kPositionTolerance) << name;
    EXPECT_LT(4 * corrected_iterations, 3 * alone_iterations)
        << name << ": " << corrected_iterations << " iterations corrected, " << alone_iterations
        << " with the factor alone";
    std::cout << name << ": iterations " << alone_iterations << " with the factor alone, "
              << corrected_iterations << " corrected\n";
  }
}

// A representative whose system is not positive definite (here a mass damping that makes the
// implicit-Euler matrix negative definite: A = (1 + h b) M + h (h + a) K with 1 + h b = -1e4)
// cannot be factorised: its diagonal stands in (z = r / |diag A|, Jacobi's up to the sign of
// the whole system), and the run goes on where stop 43 stopped with a DeviceError: CG
// converges in Jacobi's iterations (6 here, measured).
TEST_F(OpenClFactorTest, WithoutAFactorTheDiagonalStandsIn) {
  model_.damping.rayleigh_mass = -(1e4 + 1.0) / model_.dt;
  const Eigen::Vector3d so =
      scenario_.control.trajectory.position(scenario_.time.dt, scenario_.control.start);
  OpenClEnsemble jacobi = opencl(Preconditioner::jacobi, SolveLaunch::automatic);
  jacobi.set_parameters(theta_);
  const StepReport expected = jacobi.advance(so);
  OpenClEnsemble stand_in = opencl(Preconditioner::factorised, SolveLaunch::automatic);
  stand_in.set_parameters(theta_);
  const StepReport report = stand_in.advance(so);
  EXPECT_EQ(stand_in.factorisations(), 0) << "the matrix is not positive definite";
  for (int s = 0; s < kSigmaPoints; ++s) {
    EXPECT_TRUE(expected.converged[s]) << s;
    EXPECT_TRUE(report.converged[s]) << s;
    EXPECT_EQ(report.cg_iterations[s], expected.cg_iterations[s]) << s;
  }
}

// A factor made again in the background (BackgroundMaking; DeviceOptions::background_making_*),
// forced on the liver, whose factor is made in milliseconds: it is handed over at a step fixed
// when its making began, so two runs give the same bits, and CG, preconditioned a few steps
// longer by the older factor, ends within its tolerance of the run that waited for each making.
TEST_F(OpenClFactorTest, AFactorMadeInTheBackgroundGivesTheSameBitsEveryRun) {
  const auto run_with = [&](int lag) {
    OpenClEnsemble ensemble(model_, scenario_.filter->estimate, scenario_.observations.observed, kSigmaPoints,
                            test::background_making_options(lag));
    test::MakingRun made;
    made.x = run(ensemble, made.iterations, 300);
    made.makings = ensemble.factorisations();
    return made;
  };
  const test::MakingRun waited = run_with(0);
  test::expect_background_making_repeats(waited, run_with(3), run_with(3), kPositionTolerance);
}

TEST_F(OpenClFactorTest, AFactorMadeInTheBackgroundKeepsTheSpringsOfItsStep) {
  test::expect_the_making_steps_springs(
      [&](int lag) {
        DeviceOptions options;   // corrected for the sigma points' springs, as by default
        options.background_making_solves = 0.0;
        options.background_making_steps = lag;
        return std::make_unique<OpenClEnsemble>(model_, scenario_.filter->estimate, scenario_.observations.observed,
                                                kSigmaPoints, options);
      },
      scenario_, theta_);
}

TEST_F(OpenClFactorTest, TheGpuFormRefusesIt) {
  DeviceOptions options;
  options.kernel_form = KernelForm::gpu;
  options.preconditioner = Preconditioner::factorised;
  try {
    OpenClEnsemble ensemble(model_, scenario_.filter->estimate, scenario_.observations.observed,
                            kSigmaPoints, options);
    FAIL() << "the GPU form has no factor";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("CPU device only"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sigmafem
