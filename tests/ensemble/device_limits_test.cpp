// The device back ends' memory estimate (host/ensemble/device_limits.h, checked before any
// buffer is made): the state, CG and element buffers, and with OpenCL's shared factor its
// buffers too, so that a factor too large for the device is the "out of device memory"
// message and not an allocation failure.
#include "host/ensemble/device_limits.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>

namespace sigmafem {
namespace {

TEST(EnsembleMemory, CountsTheStateTheElementsAndAFactor) {
  const int nodes = 100, elements = 300, S = 4;
  const std::size_t real = sizeof(float);
  const EnsembleMemory plain = ensemble_memory(nodes, elements, S, real);
  EXPECT_EQ(plain.total, (9 * 3 * nodes * S + 33 * elements * S) * real);
  EXPECT_EQ(plain.largest, 12u * elements * S * real);

  // With a factor no Jacobi diagonals (3 N S and 12 E S reals) but L's values and row indices,
  // its column starts and ordering, a work vector per sigma point.
  const std::size_t nonzeros = 50000;
  const std::size_t jacobi = (3u * nodes * S + 12u * elements * S) * real;
  const EnsembleMemory with_factor = ensemble_memory(nodes, elements, S, real, nonzeros);
  EXPECT_EQ(with_factor.total + jacobi - plain.total,
            nonzeros * (real + sizeof(std::int32_t)) + (2 * 3 * nodes + 1) * sizeof(std::int32_t) +
                3u * nodes * S * real);
  EXPECT_EQ(with_factor.largest, nonzeros * real) << "L is the largest buffer here";
  // OpenCL's own factors: a copy of L's values a sigma point.
  const EnsembleMemory own = ensemble_memory(nodes, elements, S, real, nonzeros, FactorStorage::columns, S);
  EXPECT_EQ(own.total - with_factor.total, (S - 1) * nonzeros * real);
  EXPECT_EQ(own.largest, S * nonzeros * real);
  // Vulkan's blocks: 1.5 entries a nonzero each way, a panel index a block each way, the work
  // vector's copies; and no z (its solve finishes CG's step without it).
  const EnsembleMemory blocks = ensemble_memory(nodes, elements, S, real, nonzeros, FactorStorage::blocks);
  EXPECT_EQ(blocks.largest, nonzeros * 3 / 2 * real);
  EXPECT_EQ(blocks.total + jacobi + 3u * nodes * S * real - plain.total,
            2 * (nonzeros * 3 / 2 * real) + 2 * (nonzeros * 3 / 32) * sizeof(std::int32_t) + 3u * nodes * 8 * real);
}

TEST(EnsembleMemory, TheMessageSaysWhatIsNeededAndWhatThereIs) {
  const EnsembleMemory need = ensemble_memory(1000, 5000, 16, sizeof(float), 10'000'000);
  const std::string message = out_of_device_memory_message(need, 5000, 16, "a small device",
                                                           std::size_t{64} << 20, std::size_t{16} << 20);
  EXPECT_NE(message.find("out of device memory"), std::string::npos) << message;
  EXPECT_NE(message.find(std::to_string(need.total >> 20) + " MiB"), std::string::npos) << message;
  EXPECT_NE(message.find("a small device has 64 MiB"), std::string::npos) << message;
}

TEST(EnsembleMemory, AHierarchyMadeLaterIsHeldToWhatIsLeft) {
  const std::string message = out_of_device_memory_message("the multigrid levels", std::size_t{300} << 20,
                                                            std::size_t{900} << 20, "a small device",
                                                            std::size_t{1} << 30);
  EXPECT_NE(message.find("out of device memory: the multigrid levels need about 300 MiB more than the 900 MiB"),
            std::string::npos) << message;
  EXPECT_NE(message.find("a small device has 1024 MiB"), std::string::npos) << message;
  EXPECT_NE(message.find("--preconditioner jacobi"), std::string::npos) << message;
  DeviceOptions options;
  EXPECT_EQ(usable_device_memory(std::size_t{1} << 30, options), std::size_t{1} << 30);
  options.device_memory = std::size_t{1} << 20;
  EXPECT_EQ(usable_device_memory(std::size_t{1} << 30, options), std::size_t{1} << 20);
  EXPECT_EQ(usable_device_memory(std::size_t{1} << 10, options), std::size_t{1} << 10);
  EXPECT_EQ(memory_holder("a GPU", std::size_t{1} << 30, options), "a GPU as held by --device-memory");
  EXPECT_EQ(memory_holder("a GPU", std::size_t{1} << 10, options), "a GPU") << "the device has less than the hold";
}

}  // namespace
}  // namespace sigmafem
