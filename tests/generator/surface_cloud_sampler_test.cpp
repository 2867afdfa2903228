// SurfaceCloudSampler (host/generator/surface_cloud_sampler.h): the visible patch faces the
// camera and lies in the covered share of the depth; sampled points lie on it, spread by
// area; each frame is drawn afresh.
#include "host/generator/surface_cloud_sampler.h"

#include <gtest/gtest.h>

#include <string>

#include "filter/surface_distance.h"
#include "host/common/input_error.h"

namespace sigmafem {
namespace {

Scenario liver_cloud() {
  return load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/liver_cloud.json");
}

Eigen::VectorXd rest_positions(const Mesh& mesh) {
  Eigen::VectorXd x(3 * mesh.node_count());
  for (int i = 0; i < mesh.node_count(); ++i) x.segment<3>(3 * i) = mesh.nodes[static_cast<std::size_t>(i)];
  return x;
}

TEST(SurfaceCloudSamplerTest, ThePatchFacesTheCameraWithinTheCoveredDepth) {
  const Scenario s = liver_cloud();
  const SurfaceCloud& spec = *s.observations.surface_cloud;
  const SurfaceCloudSampler sampler(s.mesh, spec, 1);
  double near = 1e9, far = -1e9;
  for (const Eigen::Vector3d& x : s.mesh.nodes) {
    near = std::min(near, spec.view_direction.dot(x));
    far = std::max(far, spec.view_direction.dot(x));
  }
  ASSERT_FALSE(sampler.visible_triangles().empty());
  double total_area = 0.0;
  for (const std::array<int, 3>& f : boundary_faces(s.mesh)) {
    const Eigen::Vector3d a = s.mesh.nodes[f[0]], b = s.mesh.nodes[f[1]], c = s.mesh.nodes[f[2]];
    total_area += 0.5 * (b - a).cross(c - a).norm();
  }
  for (const std::array<int, 3>& f : sampler.visible_triangles()) {
    const Eigen::Vector3d a = s.mesh.nodes[f[0]], b = s.mesh.nodes[f[1]], c = s.mesh.nodes[f[2]];
    EXPECT_LT((b - a).cross(c - a).dot(spec.view_direction), 0.0) << "faces the camera";
    EXPECT_LE(spec.view_direction.dot((a + b + c) / 3.0), near + spec.coverage * (far - near) + 1e-12);
  }
  EXPECT_GT(sampler.visible_area_at_rest(), 0.05 * total_area);
  EXPECT_LT(sampler.visible_area_at_rest(), 0.5 * total_area) << "a patch, not the whole surface";
}

TEST(SurfaceCloudSamplerTest, PointsLieOnThePatchSpreadByAreaAndNewInEachFrame) {
  const Scenario s = liver_cloud();
  SurfaceCloud spec = *s.observations.surface_cloud;
  spec.points_per_frame = 20000;
  SurfaceCloudSampler sampler(s.mesh, spec, 3);
  const Eigen::VectorXd x = rest_positions(s.mesh);
  const std::vector<std::array<int, 3>>& patch = sampler.visible_triangles();
  const SurfaceSearch search(x, patch);
  const Eigen::Matrix3Xd points = sampler.sample(x);
  ASSERT_EQ(points.cols(), 20000);
  std::vector<double> count(patch.size(), 0.0);
  for (Eigen::Index i = 0; i < points.cols(); ++i) {
    const SurfacePoint at = search.closest(points.col(i));
    ASSERT_LT(at.distance, 1e-12) << "point " << i << " lies on the patch";
    count[static_cast<std::size_t>(at.triangle)] += 1.0;
  }
  // Per triangle, the count is Binomial(n, area share): within 5 standard deviations.
  for (std::size_t t = 0; t < patch.size(); ++t) {
    const Eigen::Vector3d a = x.segment<3>(3 * patch[t][0]), b = x.segment<3>(3 * patch[t][1]),
                          c = x.segment<3>(3 * patch[t][2]);
    const double share = 0.5 * (b - a).cross(c - a).norm() / sampler.visible_area_at_rest();
    const double expected = 20000.0 * share, sd = std::sqrt(20000.0 * share * (1.0 - share));
    EXPECT_NEAR(count[t], expected, 5.0 * sd + 1.0) << "triangle " << t;
  }
  EXPECT_NE(sampler.sample(x), points) << "the next frame draws new points";
}

TEST(SurfaceCloudSamplerTest, APatchWithNoTriangleIsAnError) {
  const Scenario s = liver_cloud();
  SurfaceCloud spec = *s.observations.surface_cloud;
  spec.coverage = 1e-9;   // only the single nearest point of the organ
  EXPECT_THROW(SurfaceCloudSampler(s.mesh, spec, 1), InputError);
}

}  // namespace
}  // namespace sigmafem
