// `--backend auto` (host/engine/choose_backend.h): without a GPU, OpenCL on a CPU device up to
// kCpuDeviceElements tetrahedra or where its shared factor is corrected for the sigma points'
// springs, else the CPU back end; with one, the CPU back end below
// kGpuPairs element-sigma pairs, OpenCL's GPU before Vulkan's above; a named back end is
// taken as it is.
#include "host/engine/choose_backend.h"

#include <gtest/gtest.h>

#include <string>

#include "host/common/device_options.h"
#include "host/model/model.h"
#include "host/reference/spring_correction.h"
#include "host/scenario/scenario.h"
#include "scenario_directory.h"

namespace sigmafem {
namespace {

const GpuPresence kNoGpu{};
const GpuPresence kBothGpus{"NVIDIA H200", "NVIDIA H200", ""};
const GpuPresence kVulkanGpuOnly{"", "AMD Radeon", ""};
const GpuPresence kPoclOnly{"", "", "pthread-skylake-avx512"};

TEST(ChooseBackend, WithoutAGpuTheCpuBackEnd) {
  for (long long elements : {596LL, 38144LL, 117240LL}) {
    const BackendDecision d = choose_backend(kNoGpu, elements, 64);
    EXPECT_EQ(d.backend, "cpu") << elements;
    EXPECT_NE(d.reason.find("no GPU"), std::string::npos) << d.reason;
  }
}

TEST(ChooseBackend, WithoutAGpuOpenClOnTheCpuUpToItsBound) {
  for (long long elements : {596LL, 4768LL, kCpuDeviceElements}) {
    const BackendDecision d = choose_backend(kPoclOnly, elements, 4);
    EXPECT_EQ(d.backend, "opencl") << elements;
    EXPECT_NE(d.reason.find("CPU device pthread-skylake-avx512"), std::string::npos) << d.reason;
  }
  // Above the bound the CPU back end, until the pairs reach kCpuDevicePairs (38144 x 4 on the
  // CPU back end, 38144 x 16 on OpenCL).
  for (long long elements : {kCpuDeviceElements + 1, 38144LL}) {
    const BackendDecision d = choose_backend(kPoclOnly, elements, 4);
    EXPECT_EQ(d.backend, "cpu") << elements;
    EXPECT_NE(d.reason.find("no GPU"), std::string::npos) << d.reason;
  }
  EXPECT_EQ(choose_backend(kPoclOnly, 38144, 16).backend, "opencl");
  EXPECT_EQ(choose_backend(kPoclOnly, kCpuDevicePairs / 8, 8).backend, "opencl");
  EXPECT_EQ(choose_backend(kPoclOnly, kCpuDevicePairs / 8 - 1, 8).backend, "cpu");
}

// Between the bounds OpenCL where its shared factor is corrected for each sigma point's
// springs (the 38k liver's filter step, 27 spring rows at S = 4: 71-79 against 97-100 ms,
// stop 51); not with region moduli, nor where the rows times sigma points do not fit.
TEST(ChooseBackend, WithoutAGpuOpenClWhereItsFactorIsCorrectedForTheSprings) {
  const BackendDecision d = choose_backend(kPoclOnly, 38144, 4, 0, 27);
  EXPECT_EQ(d.backend, "opencl");
  EXPECT_NE(d.reason.find("corrected for each sigma point's springs"), std::string::npos) << d.reason;
  EXPECT_EQ(choose_backend(kPoclOnly, 38144, 4, 1, 27).backend, "cpu") << "a region modulus";
  EXPECT_EQ(choose_backend(kPoclOnly, 38144, 4, 0, kSpringRowsTimesSigmaPoints / 4 + 1).backend, "cpu")
      << "too many spring rows";
  EXPECT_EQ(choose_backend(kNoGpu, 38144, 4, 0, 27).backend, "cpu") << "no OpenCL device at all";
}

TEST(ChooseBackend, TheLiverFinesSpringRowsAreCorrected) {
  // resolve_backend's rows for the 38k liver: its three estimated ligaments' nine nodes.
  const Scenario s = load_scenario(kScenarios + "liver_fine.json");
  const Model model = make_model(s);
  EXPECT_EQ(estimated_spring_rows(model, EstimatedParameters(s.filter->estimate)).size(), 27u);
}

// Sigma points that differ by estimated region moduli: where OpenCL would share one factor
// among them (below kOwnFactorsFromSigmaPoints or beyond kOwnFactorPairs) it preconditions
// them less well, and the CPU back end
// is faster (stop 49); up to it each has its own on OpenCL too; from kCpuDevicePairs pairs
// OpenCL stays (the CPU back end then shares one factor too).
TEST(ChooseBackend, WithoutAGpuRegionModuliGoToTheCpuBackEndWhereOpenClWouldShareAFactor) {
  const BackendDecision d = choose_backend(kPoclOnly, 4768, 17, 13);
  EXPECT_EQ(d.backend, "cpu");
  EXPECT_NE(d.reason.find("13 region moduli"), std::string::npos) << d.reason;
  EXPECT_EQ(choose_backend(kPoclOnly, 596, 17, 13).backend, "opencl") << "own factors";
  EXPECT_EQ(choose_backend(kPoclOnly, 596, 12, 8).backend, "cpu") << "too few sigma points for own factors";
  EXPECT_EQ(choose_backend(kPoclOnly, 596, 65, 61).backend, "opencl") << "own factors, the largest measured";
  EXPECT_EQ(choose_backend(kPoclOnly, 596, 129, 61).backend, "cpu");
  EXPECT_EQ(choose_backend(kPoclOnly, 4768, 17, 0).backend, "opencl");
  EXPECT_EQ(choose_backend(kPoclOnly, 38144, 33, 29).backend, "opencl") << "38144 x 33 pairs";
  EXPECT_EQ(choose_backend(kBothGpus, 4768, 17, 13).backend, "opencl") << "a GPU's choice is unchanged";
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
    const BackendDecision d = resolve_backend(name, model, 4, EstimatedParameters{});
    EXPECT_EQ(d.backend, name);
    EXPECT_EQ(d.reason, "given");
  }
  // auto here: a box filter (1344 x 4) is below the GPU's bound, and OpenCL's on a CPU
  // device (PoCL) when that is OpenCL's device 0.
  const GpuPresence here = find_gpus();
  EXPECT_EQ(resolve_backend("auto", model, 4, EstimatedParameters{}).backend,
            here.opencl.empty() && here.vulkan.empty() && !here.opencl_cpu.empty() ? "opencl" : "cpu");
}

}  // namespace
}  // namespace sigmafem
