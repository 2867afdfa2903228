// OpenCL's multigrid V-cycle (host/opencl/opencl_multigrid.h, kernels/opencl/multigrid.cl; the
// GPU form's preconditioner where the mesh is a refinement): on the device it is the host's
// NestedMultigrid for every sigma point, each with its own shift, with the coarsest level
// inverted or smoothed; the ensemble's CG with it follows Jacobi's trajectories in a fraction
// of the iterations, in one CG partition or several; it is refused where it cannot run.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "filter/estimation.h"
#include "filter/sigma_points.h"
#include "generated_data.h"
#include "host/common/device_error.h"
#include "host/engine/estimation_options.h"
#include "host/ensemble/device_readout.h"
#include "host/opencl/opencl_ensemble.h"
#include "host/opencl/opencl_multigrid.h"
#include "host/reference/reference_simulation.h"
#include "host/scenario/scenario.h"
#include "background_making_runs.h"
#include "requirement.h"
#include "tests/refined_liver.h"

namespace sigmafem {
namespace {

constexpr int kMultigridSigmaPoints = 4;

class OpenClMultigridTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (list_opencl_devices().empty()) SIGMAFEM_MISSING("no OpenCL platform on this machine");
    scenario_ = test::refined_liver(1);
    model_ = make_model(scenario_);
  }
  Scenario scenario_;
  Model model_;
};

// Relative difference of the device's z from the host's double V-cycle, per precision: double
// keeps the host's arithmetic to rounding (measured 1.3e-15), float32 its 6e-8 times the
// growth over the levels and the rows' sums (measured 6.8e-7).
class OpenClMultigridPrecisionTest : public OpenClMultigridTest,
                                     public ::testing::WithParamInterface<Precision> {};

TEST_P(OpenClMultigridPrecisionTest, TheDeviceVCycleIsTheHostsForEverySigmaPointWithItsShift) {
  const Precision precision = GetParam();
  const std::vector<OpenClDeviceInfo> devices = list_opencl_devices();
  if (precision == Precision::double_precision && !devices[0].has_fp64) SIGMAFEM_MISSING("no fp64 on OpenCL device 0");
  const double tolerance = precision == Precision::double_precision ? 1e-12 : 1e-5;
  OpenClDevice device(0, precision);
  device.build_program("");
  const Eigen::SparseMatrix<double> A = ReferenceSimulation(model_).system_matrix();
  const Eigen::Index rows = A.rows();
  Eigen::MatrixXd r(rows, kMultigridSigmaPoints), shift = Eigen::MatrixXd::Zero(rows, kMultigridSigmaPoints);
  for (Eigen::Index i = 0; i < rows; ++i)
    for (int s = 0; s < kMultigridSigmaPoints; ++s) r(i, s) = std::sin(0.37 * static_cast<double>(i) + s) + 0.1 * s;
  // Sigma points 1.. with stiffer or softer springs at a few rows, sigma point 0 without.
  for (Eigen::Index i = 0; i < rows; i += 97)
    for (int s = 1; s < kMultigridSigmaPoints; ++s) shift(i, s) = (s - 1.5) * 0.5 * A.coeff(i, i);
  for (int dense_rows : {NestedMultigrid::kDenseCoarsestRows, 0}) {
    NestedMultigrid multigrid(nested_prolongations(model_), dense_rows);
    ASSERT_TRUE(multigrid.set_matrix(A));
    OpenClMultigrid on_device(device, kMultigridSigmaPoints);
    on_device.upload(multigrid);
    EXPECT_EQ(on_device.device_bytes(), multigrid_memory(multigrid, kMultigridSigmaPoints, device.real_size()))
        << "the memory check's count";
    const std::vector<double> shift_rows = to_sigma_rows(shift);
    on_device.upload_shift(shift_rows);
    const std::vector<unsigned char> r_bytes = to_device_reals(to_sigma_rows(r), precision);
    cl::Buffer r_buffer(device.context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, r_bytes.size(),
                        const_cast<unsigned char*>(r_bytes.data()));
    cl::Buffer z_buffer(device.context(), CL_MEM_READ_WRITE, r_bytes.size());
    on_device.enqueue(r_buffer, z_buffer);
    std::vector<unsigned char> z_bytes(r_bytes.size());
    device.queue().enqueueReadBuffer(z_buffer, CL_TRUE, 0, z_bytes.size(), z_bytes.data());
    const Eigen::MatrixXd z = from_sigma_rows(from_device_reals(z_bytes.data(), z_bytes.size() / device.real_size(), precision),
                                              static_cast<std::size_t>(rows), kMultigridSigmaPoints);
    for (int s = 0; s < kMultigridSigmaPoints; ++s) {
      Eigen::VectorXd expected;
      multigrid(r.col(s), expected, shift.col(s));
      EXPECT_LE((z.col(s) - expected).cwiseAbs().maxCoeff(), tolerance * expected.cwiseAbs().maxCoeff())
          << "sigma point " << s << ", coarsest inverted up to " << dense_rows << " rows";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Precisions, OpenClMultigridPrecisionTest,
                         ::testing::Values(Precision::single, Precision::double_precision),
                         [](const ::testing::TestParamInfo<Precision>& param_info) {
                           return param_info.param == Precision::single ? std::string("Single") : std::string("Double");
                         });

// The GPU form on PoCL, float32: 10 steps of the refined liver with the ligaments of each
// sigma point apart, Jacobi against the V-cycle, in one CG partition and in three.
TEST_F(OpenClMultigridTest, TheGpuFormsCgFollowsJacobiInAFifthOfItsIterationsOrFewer) {
  const Eigen::MatrixXd theta = test::spread_log_stiffness(scenario_, model_, kMultigridSigmaPoints, 0.5);
  const auto run = [&](Preconditioner preconditioner, int partitions, long& iterations, int& makings) {
    DeviceOptions options;
    options.kernel_form = KernelForm::gpu;
    options.preconditioner = preconditioner;
    options.cg_partitions = partitions;
    OpenClEnsemble ensemble(model_, scenario_.filter->estimate, scenario_.observations.observed, kMultigridSigmaPoints,
                            options);
    EXPECT_EQ(ensemble.multigrid(), preconditioner == Preconditioner::automatic);
    const Eigen::MatrixXd x = test::run_steps(ensemble, scenario_, theta, 10, iterations);
    makings = ensemble.factorisations();
    return x;
  };
  long jacobi_iterations = 0;
  int jacobi_makings = 0;
  const Eigen::MatrixXd jacobi = run(Preconditioner::jacobi, 1, jacobi_iterations, jacobi_makings);
  EXPECT_EQ(jacobi_makings, 0);
  for (int partitions : {1, 3}) {
    long iterations = 0;
    int makings = 0;
    const Eigen::MatrixXd multigrid = run(Preconditioner::automatic, partitions, iterations, makings);
    // Each CG stops within 1e-6 of |b| from its own preconditioner: the positions agree to
    // 1e-6 m (the organ moves by millimetres over these steps; measured 3.0e-8 m).
    EXPECT_LE((multigrid - jacobi).cwiseAbs().maxCoeff(), 1e-6) << partitions << " partitions";
    // Measured: 8876 iterations (Jacobi) against 522, one making of the hierarchy.
    EXPECT_LE(5 * iterations, jacobi_iterations) << partitions << " partitions";
    EXPECT_GE(makings, 1);
  }
}

// The filter on data generated for the refined liver (60 steps, the CPU reference's truth):
// the GPU form's estimates with the V-cycle are those with Jacobi within the 0.5% that every
// device back end keeps from the CPU back end's (tests/conformance/whole_run_test.cpp): each CG
// stops within 1e-6 of |b| from its own preconditioner, and the filter, still moving after 60
// steps, sees the difference (measured 0.12% at most).
TEST_F(OpenClMultigridTest, TheFiltersEstimatesAreJacobisOnDataGeneratedForTheRefinedLiver) {
  Scenario s = scenario_;
  s.time.steps = 60;
  const ObservationTable data = test::generated_observations(s);
  const EstimationOptions options = estimation_options(s);
  Model model = make_model(s);
  const EstimatedParameters estimated = estimated_parameters(*s.filter, model);
  const auto estimate = [&](Preconditioner preconditioner) {
    DeviceOptions device;
    device.kernel_form = KernelForm::gpu;
    device.preconditioner = preconditioner;
    OpenClEnsemble ensemble(model, estimated, s.observations.observed,
                            sigma_point_count(options.roukf.sigma_points, estimated.count()), device);
    const EstimationRun run = run_estimation(ensemble, options, data.times, data.so, data.points, {});
    EXPECT_TRUE(run.complete) << run.stop_reason;
    return run.steps.back().stiffness;
  };
  const Eigen::VectorXd jacobi = estimate(Preconditioner::jacobi);
  const Eigen::VectorXd multigrid = estimate(Preconditioner::automatic);
  ASSERT_EQ(jacobi.size(), multigrid.size());
  for (Eigen::Index j = 0; j < jacobi.size(); ++j)
    EXPECT_NEAR(multigrid[j] / jacobi[j], 1.0, 5e-3) << "parameter " << j << ": " << multigrid[j] << " against " << jacobi[j];
}

// The hierarchy made again in the background after the first (host/reference/background_making.h),
// made often here (its making counted as one V-cycle in the refresh rule), handed over 3 steps
// after it began: two runs give the same bits, within CG's tolerance of the run that waited.
TEST_F(OpenClMultigridTest, AHierarchyMadeInTheBackgroundGivesTheSameBitsEveryRun) {
  const Eigen::MatrixXd theta = test::spread_log_stiffness(scenario_, model_, kMultigridSigmaPoints, 0.5);
  const auto run_with = [&](int lag) {
    DeviceOptions options = test::background_making_options(lag);
    options.kernel_form = KernelForm::gpu;
    options.multigrid_making_cycles = 1.0;
    OpenClEnsemble ensemble(model_, scenario_.filter->estimate, scenario_.observations.observed, kMultigridSigmaPoints,
                            options);
    EXPECT_TRUE(ensemble.multigrid());
    return test::multigrid_making_run(ensemble, scenario_, theta);
  };
  const test::MakingRun waited = run_with(0);
  test::expect_background_making_repeats(waited, run_with(3), run_with(3), 1e-6);
}

TEST_F(OpenClMultigridTest, ItsLevelsAreCheckedAgainstTheDevicesMemory) {
  DeviceOptions options;
  options.kernel_form = KernelForm::gpu;
  test::expect_multigrid_memory_checked<OpenClEnsemble>(scenario_, model_, kMultigridSigmaPoints, options);
}

TEST_F(OpenClMultigridTest, IsRefusedOnTheCpuFormAndOnAMeshThatNoRefinementMade) {
  DeviceOptions options;
  options.preconditioner = Preconditioner::multigrid;
  options.kernel_form = KernelForm::cpu;
  EXPECT_THROW(OpenClEnsemble(model_, scenario_.filter->estimate, scenario_.observations.observed, kMultigridSigmaPoints, options),
               DeviceError);
  options.kernel_form = KernelForm::gpu;
  const Scenario shipped = test::refined_liver(0);
  EXPECT_THROW(OpenClEnsemble(make_model(shipped), shipped.filter->estimate, shipped.observations.observed, kMultigridSigmaPoints,
                              options),
               DeviceError);
}

}  // namespace
}  // namespace sigmafem
