// The device back ends' memory estimate (host/ensemble/device_limits.h, checked before any
// buffer is made): the state, CG and element buffers, and with OpenCL's shared factor its
// buffers too, so that a factor too large for the device is the "out of device memory"
// message and not an allocation failure.
#include "host/ensemble/device_limits.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <string>

namespace sigmafem {
namespace {

// OpenCL's GPU form lays CG's groups over sigma points side by side where the rows are in
// partitions: a sector's worth (8 floats, 4 doubles) or all S where fewer, and as many groups
// as with a sigma point a group (S x P: the partitions grow with the lanes).
TEST(CgGroups, SigmaPointsSideBySideInPartitionsAsManyGroupsAsBefore) {
  const int small = 100, large = 30036;   // 300 rows: one partition; 90108 rows: the most, 64
  ASSERT_EQ(cg_partitions(small, 0), 1);
  ASSERT_EQ(cg_partitions(large, 0), kMostPartitions);
  // A small mesh: a group per sigma point in cg_iteration, as before.
  EXPECT_EQ(cg_groups(small, 16, sizeof(float), 64, 0, 0).sigma_lanes, 1);
  EXPECT_EQ(cg_groups(small, 16, sizeof(float), 64, 0, 0).partitions, 1);
  for (int S : {1, 4, 16, 65}) {
    const CgGroups groups = cg_groups(large, S, sizeof(float), 64, 0, 0);
    EXPECT_EQ(groups.sigma_lanes, S == 1 ? 1 : S == 4 ? 4 : 8) << S;
    EXPECT_EQ(groups.partitions, kMostPartitions * groups.sigma_lanes) << S;
    const int blocks = (S + groups.sigma_lanes - 1) / groups.sigma_lanes;
    EXPECT_GE(blocks * groups.partitions, S * kMostPartitions) << S;
  }
  EXPECT_EQ(cg_groups(large, 16, sizeof(double), 64, 0, 0).sigma_lanes, 4);
  // Forced partitions keep a lane a sigma point (the benchmarks' one group per sigma point);
  // forced lanes are taken as they are, and a number that is not a power of two dividing the
  // group is refused.
  EXPECT_EQ(cg_groups(large, 4, sizeof(float), 64, 1, 0).sigma_lanes, 1);
  EXPECT_EQ(cg_groups(small, 4, sizeof(float), 64, 3, 0).sigma_lanes, 1);
  EXPECT_EQ(cg_groups(small, 4, sizeof(float), 64, 3, 0).partitions, 3);
  EXPECT_EQ(cg_groups(small, 4, sizeof(float), 64, 3, 2).sigma_lanes, 2);
  EXPECT_EQ(cg_groups(small, 4, sizeof(float), 64, 0, 8).sigma_lanes, 8);
  EXPECT_THROW(cg_groups(small, 4, sizeof(float), 64, 0, 3), std::invalid_argument);
  EXPECT_THROW(cg_groups(small, 4, sizeof(float), 64, 0, 128), std::invalid_argument);
}

TEST(EnsembleMemory, CountsTheStateTheElementsAndAFactor) {
  const int nodes = 100, elements = 300, S = 4;
  const std::size_t real = sizeof(float);
  const EnsembleMemory plain = ensemble_memory(nodes, elements, S, real);
  EXPECT_EQ(plain.total, (9 * 3 * nodes * S + 33 * elements * S) * real);
  EXPECT_EQ(plain.largest, 12u * elements * S * real);
  // Vulkan's frames: their first two rows, 6 numbers of 9.
  EXPECT_EQ(plain.total - ensemble_memory(nodes, elements, S, real, 0, FactorStorage::columns, 1, 6).total,
            3u * elements * S * real);

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
