// The device ensembles' one table of buffers (host/ensemble/device_buffers.h): every buffer
// once, in order, with the sizes and first contents the kernels expect, and each kernel's
// buffers at the slots of kernels/shared/device_layout.h, which the shaders bind by.
#include "host/ensemble/device_buffers.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "device_layout.h"
#include "host/model/model.h"
#include "host/scenario/scenario.h"

namespace sigmafem {
namespace {

class DeviceBuffersTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scenario_ = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.json");
    model_ = make_model(scenario_);
  }
  const DeviceBufferSpec& spec(const std::vector<DeviceBufferSpec>& specs, DeviceBuffer id) {
    return specs[static_cast<std::size_t>(id)];
  }
  Scenario scenario_;
  Model model_;
};

TEST_F(DeviceBuffersTest, EveryBufferOnceInOrderWithTheLayoutsSizes) {
  const int S = 5, N = model_.node_count(), E = model_.element_count();
  const std::vector<DeviceBufferSpec> specs =
      device_buffer_specs(model_, scenario_.observations.observed, S, 42, {0, 3});
  ASSERT_EQ(specs.size(), static_cast<std::size_t>(kDeviceBufferCount));
  for (int i = 0; i < kDeviceBufferCount; ++i) {
    EXPECT_EQ(specs[i].id, static_cast<DeviceBuffer>(i));
    EXPECT_GE(specs[i].count, 1u);
    // Contents, where given, fill the buffer exactly.
    if (!specs[i].reals.empty()) {
      EXPECT_EQ(specs[i].reals.size(), specs[i].count) << specs[i].what;
    }
    if (specs[i].integer) {
      EXPECT_EQ(specs[i].integers.size(), specs[i].count) << specs[i].what;
    }
    EXPECT_FALSE(specs[i].integer && !specs[i].reals.empty()) << specs[i].what;
  }
  const std::size_t dof = 3 * static_cast<std::size_t>(N) * S;
  EXPECT_EQ(spec(specs, DeviceBuffer::x).count, dof);
  EXPECT_EQ(spec(specs, DeviceBuffer::element_out).count, 12 * static_cast<std::size_t>(E) * S);
  EXPECT_EQ(spec(specs, DeviceBuffer::element_rest).count, SF_REST_STRIDE * static_cast<std::size_t>(E));
  EXPECT_EQ(spec(specs, DeviceBuffer::constants).count, 42u);
  EXPECT_EQ(spec(specs, DeviceBuffer::partial).count, 4u * S * 3);   // 4 sums per group
  EXPECT_TRUE(spec(specs, DeviceBuffer::element_nodes).integer);
  EXPECT_FALSE(spec(specs, DeviceBuffer::mass).integer);
  // Every sigma point starts at rest; all_active is S ones.
  const std::vector<double>& x = spec(specs, DeviceBuffer::x).reals;
  for (int n = 0; n < N; n += 37)
    for (int s = 0; s < S; ++s) EXPECT_EQ(x[(3 * static_cast<std::size_t>(n) + 1) * S + s], model_.rest_positions[n][1]);
  const std::vector<int>& all_active = spec(specs, DeviceBuffer::all_active).integers;
  EXPECT_EQ(std::count(all_active.begin(), all_active.end(), 1), S);
  // The node incidence lists every element corner once.
  EXPECT_EQ(spec(specs, DeviceBuffer::incidence).count, 4 * static_cast<std::size_t>(E));
  // Jacobi's diagonals, which a factor's kernels leave out, are one element with a factor.
  EXPECT_EQ(spec(specs, DeviceBuffer::element_diagonal).count, 12 * static_cast<std::size_t>(E) * S);
  EXPECT_EQ(spec(specs, DeviceBuffer::inverse_diagonal).count, dof);
  DeviceBufferSizes factor{0, 1, 1000};
  factor.jacobi_diagonals = false;
  const std::vector<DeviceBufferSpec> with_factor =
      device_buffer_specs(model_, scenario_.observations.observed, S, 42, factor);
  EXPECT_EQ(spec(with_factor, DeviceBuffer::element_diagonal).count, 1u);
  EXPECT_EQ(spec(with_factor, DeviceBuffer::inverse_diagonal).count, 1u);
  EXPECT_EQ(spec(with_factor, DeviceBuffer::element_out).count, 12 * static_cast<std::size_t>(E) * S);
  // A larger element_out asked for (the chunks' copies on a CPU) is given.
  EXPECT_EQ(spec(device_buffer_specs(model_, scenario_.observations.observed, S, 42, {5 * dof, 1}),
                 DeviceBuffer::element_out)
                .count,
            std::max(5 * dof, 12 * static_cast<std::size_t>(E) * S));
}

TEST_F(DeviceBuffersTest, EachKernelsBuffersSitAtTheSharedSlots) {
  EXPECT_EQ(buffer_slot(DeviceKernel::element_rhs, DeviceBuffer::x), SF_ELEMENT_RHS_X);
  EXPECT_EQ(buffer_slot(DeviceKernel::element_product, DeviceBuffer::d), SF_ELEMENT_PRODUCT_D);
  EXPECT_EQ(buffer_slot(DeviceKernel::node_product, DeviceBuffer::q), SF_NODE_PRODUCT_Q);
  EXPECT_EQ(buffer_slot(DeviceKernel::recenter, DeviceBuffer::v), SF_RECENTER_V);
  EXPECT_EQ(buffer_slot(DeviceKernel::vulkan_cg_start, DeviceBuffer::dv), SF_CG_START_DV);
  EXPECT_EQ(buffer_slot(DeviceKernel::vulkan_cg_iteration, DeviceBuffer::dv), SF_CG_ITERATION_DV);
  // The node kernels (and Vulkan's cg_start, which gathers the warm start's rows) begin with
  // what a node row reads, in the same slots.
  const std::vector<DeviceBuffer>& rhs = kernel_buffers(DeviceKernel::node_rhs);
  const std::vector<DeviceBuffer>& product = kernel_buffers(DeviceKernel::node_product);
  const std::vector<DeviceBuffer>& start = kernel_buffers(DeviceKernel::vulkan_cg_start);
  for (int slot = 0; slot <= SF_NODE_MASS; ++slot) {
    EXPECT_EQ(rhs[slot], product[slot]);
    EXPECT_EQ(start[slot], product[slot]);
  }
  // No kernel takes a buffer twice.
  for (DeviceKernel k : {DeviceKernel::element_rhs, DeviceKernel::node_rhs, DeviceKernel::element_product,
                         DeviceKernel::node_product, DeviceKernel::state_update,
                         DeviceKernel::observation_gather, DeviceKernel::recenter,
                         DeviceKernel::vulkan_cg_start, DeviceKernel::vulkan_cg_iteration}) {
    std::vector<DeviceBuffer> sorted = kernel_buffers(k);
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end());
  }
  // element_product on other inputs (the warm start's dv, all sigma points active).
  const std::vector<DeviceBuffer> warm = with_buffer(
      with_buffer(kernel_buffers(DeviceKernel::element_product), DeviceBuffer::d, DeviceBuffer::dv),
      DeviceBuffer::active, DeviceBuffer::all_active);
  EXPECT_EQ(warm[SF_ELEMENT_PRODUCT_D], DeviceBuffer::dv);
  EXPECT_EQ(warm[SF_ELEMENT_PRODUCT_ACTIVE], DeviceBuffer::all_active);
}

TEST_F(DeviceBuffersTest, TheEstimatedLigamentsShareOutTheirStiffnessPerNode) {
  const int S = 2;
  std::vector<double> ligament_k =
      spec(device_buffer_specs(model_, scenario_.observations.observed, S, 1, {}), DeviceBuffer::ligament_k).reals;
  const std::vector<double> before = ligament_k;
  Eigen::MatrixXd theta(1, S);
  theta << std::log(120.0), std::log(480.0);
  EXPECT_EQ(parameters_from_theta(model_, {1}, theta, S, ligament_k).rows(), 0);
  const double nodes = static_cast<double>(model_.ligaments[1].nodes.size());
  EXPECT_NEAR(ligament_k[1 * S + 0], 120.0 / nodes, 1e-12);
  EXPECT_NEAR(ligament_k[1 * S + 1], 480.0 / nodes, 1e-12);
  // The ligaments not estimated keep the model's share.
  EXPECT_EQ(ligament_k[0], before[0]);
  EXPECT_EQ(ligament_k[2 * S + 1], before[2 * S + 1]);
  EXPECT_NEAR(before[0], model_.ligaments[0].stiffness / static_cast<double>(model_.ligaments[0].nodes.size()), 1e-12);
}

// A region's elements name its slot in their rest state (slot 0: no estimated region), and
// theta's region rows become the scales of the model's modulus the kernels multiply by.
TEST_F(DeviceBuffersTest, AnEstimatedRegionsElementsNameItsSlotAndTakeTheirScale) {
  Model model = model_;
  model.regions.push_back({"unestimated", {0, 1}, 5000.0});
  model.regions.push_back({"tumour", {2, 7}, 2000.0});
  const int S = 2;
  const std::vector<double> rest =
      spec(device_buffer_specs(model, scenario_.observations.observed, S, 1, {}, {1}), DeviceBuffer::element_rest).reals;
  for (int e : {0, 1, 3, 8}) EXPECT_EQ(rest[16 * e + SF_REST_REGION_SLOT], 0.0) << e;
  for (int e : {2, 7}) EXPECT_EQ(rest[16 * e + SF_REST_REGION_SLOT], 1.0) << e;
  std::vector<double> ligament_k(static_cast<std::size_t>(model.ligaments.size()) * S, 0.0);
  Eigen::MatrixXd theta(2, S);
  theta << std::log(100.0), std::log(200.0), std::log(3000.0), std::log(10000.0);
  const Eigen::MatrixXd scales = parameters_from_theta(model, EstimatedParameters({0}, {1}), theta, S, ligament_k);
  ASSERT_EQ(scales.rows(), 1);
  EXPECT_NEAR(scales(0, 0), 1.5, 1e-12);
  EXPECT_NEAR(scales(0, 1), 5.0, 1e-12);
}

}  // namespace
}  // namespace sigmafem
