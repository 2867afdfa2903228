// make_ensemble's report of the preconditioner each back end runs CG with (summary.json and
// report.json say it): the CPU back end's factors unless Jacobi is asked; OpenCL's shared
// factor on a CPU device unless Jacobi is asked, on a GPU only when asked (and then refused);
// Vulkan always Jacobi.
#include "host/engine/make_ensemble.h"
#include "host/opencl/opencl_ensemble.h"
#include "host/vulkan/vulkan_ensemble.h"

#include <gtest/gtest.h>

namespace sigmafem {
namespace {

DeviceOptions with(Preconditioner preconditioner) {
  DeviceOptions options;
  options.preconditioner = preconditioner;
  return options;
}

TEST(MakeEnsemble, SaysWhichPreconditionerEachBackEndRuns) {
  EXPECT_EQ(preconditioner_used("cpu", with(Preconditioner::automatic)), "factorised");
  EXPECT_EQ(preconditioner_used("cpu", with(Preconditioner::factorised)), "factorised");
  EXPECT_EQ(preconditioner_used("cpu", with(Preconditioner::jacobi)), "jacobi");
  EXPECT_EQ(preconditioner_used("opencl", with(Preconditioner::factorised)), "factorised");
  EXPECT_EQ(preconditioner_used("opencl", with(Preconditioner::jacobi)), "jacobi");
  EXPECT_EQ(preconditioner_used("vulkan", with(Preconditioner::jacobi)), "jacobi");
  EXPECT_EQ(preconditioner_used("vulkan", with(Preconditioner::factorised)), "factorised");
}

// Vulkan's default since stop 53: the factor on a CPU device (lavapipe), Jacobi on a GPU.
TEST(MakeEnsemble, VulkansDefaultIsTheFactorOnACpuDeviceOnly) {
  EXPECT_TRUE(vulkan_uses_factor(Preconditioner::automatic, "cpu"));
  EXPECT_FALSE(vulkan_uses_factor(Preconditioner::automatic, "discrete gpu"));
  EXPECT_FALSE(vulkan_uses_factor(Preconditioner::jacobi, "cpu"));
  EXPECT_TRUE(vulkan_uses_factor(Preconditioner::factorised, "discrete gpu"));   // refused by the ensemble
  const std::vector<VulkanDeviceInfo> devices = list_vulkan_devices();
  if (devices.empty()) GTEST_SKIP() << "no Vulkan device";
  EXPECT_EQ(preconditioner_used("vulkan", with(Preconditioner::automatic)),
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
  EXPECT_EQ(preconditioner_used("opencl", with(Preconditioner::automatic)),
            devices[0].type == "cpu" ? "factorised" : "jacobi");
}

}  // namespace
}  // namespace sigmafem
