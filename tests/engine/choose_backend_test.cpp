// `--backend auto` (host/engine/choose_backend.h): the CPU back end without a GPU or below
// kGpuPairs element-sigma pairs, OpenCL's GPU before Vulkan's above; a named back end is
// taken as it is.
#include "host/engine/choose_backend.h"

#include <gtest/gtest.h>

#include <string>

#include "host/model/model.h"
#include "host/scenario/scenario.h"
#include "scenario_directory.h"

namespace sigmafem {
namespace {

const GpuPresence kNoGpu{};
const GpuPresence kBothGpus{"NVIDIA H200", "NVIDIA H200"};
const GpuPresence kVulkanGpuOnly{"", "AMD Radeon"};

TEST(ChooseBackend, WithoutAGpuTheCpuBackEnd) {
  for (long long elements : {596LL, 38144LL, 117240LL}) {
    const BackendDecision d = choose_backend(kNoGpu, elements, 64);
    EXPECT_EQ(d.backend, "cpu") << elements;
    EXPECT_NE(d.reason.find("no GPU"), std::string::npos) << d.reason;
  }
}

TEST(ChooseBackend, AGpuFromEnoughWorkAndOpenClFirst) {
  // The liver's filter step (596 x 4) stays on the CPU; the 4768 liver at S = 16 goes to the GPU.
  EXPECT_EQ(choose_backend(kBothGpus, 596, 4).backend, "cpu");
  EXPECT_EQ(choose_backend(kBothGpus, 4768, 16).backend, "opencl");
  const BackendDecision at_the_bound = choose_backend(kBothGpus, kGpuPairs / 4, 4);
  EXPECT_EQ(at_the_bound.backend, "opencl");
  EXPECT_NE(at_the_bound.reason.find("NVIDIA H200"), std::string::npos) << at_the_bound.reason;
  const BackendDecision below = choose_backend(kBothGpus, kGpuPairs / 4 - 1, 4);
  EXPECT_EQ(below.backend, "cpu");
  EXPECT_NE(below.reason.find("too small"), std::string::npos) << below.reason;
  EXPECT_EQ(choose_backend(kVulkanGpuOnly, 38144, 4).backend, "vulkan");
}

TEST(ChooseBackend, ANamedBackEndIsTakenAsItIs) {
  const Model model = make_model(load_scenario(kScenarios + "box.json"));
  for (const char* name : {"cpu", "opencl", "vulkan"}) {
    const BackendDecision d = resolve_backend(name, model, 4);
    EXPECT_EQ(d.backend, name);
    EXPECT_EQ(d.reason, "given");
  }
  // auto here: whatever this machine has, a box filter (1344 x 4) is below the bound.
  EXPECT_EQ(resolve_backend("auto", model, 4).backend, "cpu");
}

}  // namespace
}  // namespace sigmafem
