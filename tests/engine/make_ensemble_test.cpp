// make_ensemble's report of the preconditioner each back end runs CG with (summary.json and
// report.json say it): the CPU back end's factors unless Jacobi is asked; OpenCL's shared
// factor on a CPU device unless Jacobi is asked, on a GPU only when asked (and then refused);
// Vulkan the factor on a CPU device; OpenCL's GPU form the multigrid V-cycle where the mesh
// was refined.
#include "host/common/input_error.h"
#include "host/engine/make_ensemble.h"
#include "host/opencl/opencl_ensemble.h"
#include "host/scenario/scenario.h"
#include "host/vulkan/vulkan_ensemble.h"

#include <gtest/gtest.h>

#include "tests/refined_liver.h"

namespace sigmafem {
namespace {

DeviceOptions with(Preconditioner preconditioner) {
  DeviceOptions options;
  options.preconditioner = preconditioner;
  return options;
}

// The liver as shipped (not a refinement) or refined once.
Model liver_refined(int refine) { return make_model(test::refined_liver(refine)); }

// preconditioner_used on the shipped liver.
std::string used_on_liver(const std::string& backend, const DeviceOptions& options) {
  static const Model model = liver_refined(0);
  return preconditioner_used(backend, options, model);
}

TEST(MakeEnsemble, SaysWhichPreconditionerEachBackEndRuns) {
  EXPECT_EQ(used_on_liver("cpu", with(Preconditioner::automatic)), "factorised");
  EXPECT_EQ(used_on_liver("cpu", with(Preconditioner::factorised)), "factorised");
  EXPECT_EQ(used_on_liver("cpu", with(Preconditioner::jacobi)), "jacobi");
  EXPECT_EQ(used_on_liver("opencl", with(Preconditioner::factorised)), "factorised");
  EXPECT_EQ(used_on_liver("opencl", with(Preconditioner::jacobi)), "jacobi");
  EXPECT_EQ(used_on_liver("vulkan", with(Preconditioner::jacobi)), "jacobi");
  EXPECT_EQ(used_on_liver("vulkan", with(Preconditioner::factorised)), "factorised");
}

// Vulkan's default since stop 53: the factor on a CPU device (lavapipe), Jacobi on a GPU.
TEST(MakeEnsemble, VulkansDefaultIsTheFactorOnACpuDeviceOnly) {
  EXPECT_TRUE(vulkan_uses_factor(Preconditioner::automatic, "cpu"));
  EXPECT_FALSE(vulkan_uses_factor(Preconditioner::automatic, "discrete gpu"));
  EXPECT_FALSE(vulkan_uses_factor(Preconditioner::jacobi, "cpu"));
  EXPECT_TRUE(vulkan_uses_factor(Preconditioner::factorised, "discrete gpu"));   // refused by the ensemble
  const std::vector<VulkanDeviceInfo> devices = list_vulkan_devices();
  if (devices.empty()) GTEST_SKIP() << "no Vulkan device";
  EXPECT_EQ(used_on_liver("vulkan", with(Preconditioner::automatic)),
            devices[0].type == "cpu" ? "factorised" : "jacobi");
}

TEST(MakeEnsemble, OpenClsDefaultIsTheFactorOnItsCpuFormOnly) {
  EXPECT_TRUE(opencl_uses_factor(Preconditioner::automatic, opencl_cpu_form(KernelForm::automatic, "cpu")));
  EXPECT_FALSE(opencl_uses_factor(Preconditioner::automatic, opencl_cpu_form(KernelForm::automatic, "gpu")));
  EXPECT_FALSE(opencl_uses_factor(Preconditioner::jacobi, true));
  EXPECT_TRUE(opencl_uses_factor(Preconditioner::factorised, false));   // refused by the ensemble
  EXPECT_TRUE(opencl_cpu_form(KernelForm::cpu, "gpu"));
  EXPECT_FALSE(opencl_cpu_form(KernelForm::gpu, "cpu"));
  // The report asks the device: device 0 here, when there is one.
  const std::vector<OpenClDeviceInfo> devices = list_opencl_devices();
  if (devices.empty()) GTEST_SKIP() << "no OpenCL device";
  EXPECT_EQ(used_on_liver("opencl", with(Preconditioner::automatic)),
            devices[0].type == "cpu" ? "factorised" : "jacobi");
}

// OpenCL's GPU form: the multigrid V-cycle by default where the mesh is a refinement; asked on
// the CPU form or an unrefined mesh, the ensemble refuses it (OpenClMultigridTest).
TEST(MakeEnsemble, OpenClsGpuFormDefaultsToTheMultigridWhereTheMeshWasRefined) {
  EXPECT_TRUE(opencl_uses_multigrid(Preconditioner::automatic, false, true));
  EXPECT_FALSE(opencl_uses_multigrid(Preconditioner::automatic, false, false));
  EXPECT_FALSE(opencl_uses_multigrid(Preconditioner::automatic, true, true));
  EXPECT_FALSE(opencl_uses_multigrid(Preconditioner::jacobi, false, true));
  EXPECT_TRUE(opencl_uses_multigrid(Preconditioner::multigrid, true, false));   // refused by the ensemble
  DeviceOptions gpu_form = with(Preconditioner::automatic);
  gpu_form.kernel_form = KernelForm::gpu;
  EXPECT_EQ(preconditioner_used("opencl", gpu_form, liver_refined(1)), "multigrid");
  EXPECT_EQ(preconditioner_used("opencl", gpu_form, liver_refined(0)), "jacobi");
  EXPECT_THROW(make_ensemble("cpu", liver_refined(1), EstimatedParameters(), ObservedPoints(), 4, with(Preconditioner::multigrid)),
               InputError);
}

}  // namespace
}  // namespace sigmafem
