// The OpenCL device layer's failures are DeviceErrors that say what to do: kernels that fail
// to build come with the build log, an ensemble too big for the device says how much it
// needs and how much there is (before allocating anything).
#include "host/opencl/opencl_device.h"

#include <gtest/gtest.h>

#include <string>

#include "host/model/model.h"
#include "host/opencl/opencl_ensemble.h"
#include "host/scenario/scenario.h"
#include "requirement.h"

namespace sigmafem {
namespace {

class OpenClDeviceTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (list_opencl_devices().empty()) SIGMAFEM_MISSING("no OpenCL platform on this machine");
  }
};

TEST_F(OpenClDeviceTest, ListsDevicesWithTheirProperties) {
  const auto devices = list_opencl_devices();
  for (std::size_t i = 0; i < devices.size(); ++i) {
    EXPECT_EQ(devices[i].index, static_cast<int>(i));
    EXPECT_FALSE(devices[i].name.empty());
    EXPECT_GT(devices[i].global_memory, 0u);
    EXPECT_GT(devices[i].max_allocation, 0u);
  }
}

TEST_F(OpenClDeviceTest, KernelsThatFailToBuildShowTheBuildLog) {
  OpenClDevice device(0, Precision::single);
  try {
    // A define that turns a kernel's loop bound into a syntax error.
    device.build_program("-DSF_SIGMA_BLOCK=+");
    FAIL() << "expected a build failure";
  } catch (const DeviceError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("failed to build"), std::string::npos) << message;
    EXPECT_NE(message.find("Build log"), std::string::npos) << message;
    EXPECT_NE(message.find("error"), std::string::npos) << "the log itself: " << message;
  }
}

TEST_F(OpenClDeviceTest, TooBigAnEnsembleSaysHowMuchItNeeds) {
  const Scenario scenario = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.json");
  const Model model = make_model(scenario);
  // 1344 tetrahedra x 12 x S floats in one buffer: S = 2^22 needs about 270 GB (and the host's
  // per-sigma step constants, made before the check, 0.7 GB; at 2^26 they took 6-14 s).
  try {
    OpenClEnsemble ensemble(model, {0}, {}, 1 << 22, DeviceOptions{});
    FAIL() << "expected an out-of-memory error";
  } catch (const DeviceError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("out of device memory"), std::string::npos) << message;
    EXPECT_NE(message.find("MiB"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace sigmafem
