// closest_point_weights and SurfaceSearch (filter/surface_distance.h): each Voronoi region of
// a triangle gives its exact nearest point; the search over a whole organ's surface finds the
// same distance as trying every triangle.
#include "filter/surface_distance.h"

#include <gtest/gtest.h>

#include <random>
#include <string>

#include "host/mesh/mesh.h"
#include "host/scenario/scenario.h"

namespace sigmafem {
namespace {

const Eigen::Vector3d kA(0.0, 0.0, 0.0), kB(2.0, 0.0, 0.0), kC(0.0, 2.0, 0.0);

Eigen::Vector3d point_of(const Eigen::Vector3d& w) { return w[0] * kA + w[1] * kB + w[2] * kC; }

TEST(SurfaceDistanceTest, EachRegionOfATriangleGivesItsNearestPoint) {
  struct Case {
    const char* region;
    Eigen::Vector3d p, nearest;
  };
  const Case cases[] = {
      {"face", {0.5, 0.5, 3.0}, {0.5, 0.5, 0.0}},
      {"corner a", {-1.0, -1.0, 0.5}, kA},
      {"corner b", {3.0, -0.5, -1.0}, kB},
      {"corner c", {-0.5, 3.0, 0.0}, kC},
      {"edge ab", {1.0, -2.0, 1.0}, {1.0, 0.0, 0.0}},
      {"edge ac", {-1.0, 1.5, -2.0}, {0.0, 1.5, 0.0}},
      {"edge bc", {2.0, 2.0, 0.25}, {1.0, 1.0, 0.0}},
  };
  for (const Case& c : cases) {
    const Eigen::Vector3d w = closest_point_weights(c.p, kA, kB, kC);
    EXPECT_NEAR(w.sum(), 1.0, 1e-15) << c.region;
    EXPECT_GE(w.minCoeff(), 0.0) << c.region;
    EXPECT_LT((point_of(w) - c.nearest).norm(), 1e-14) << c.region;
  }
}

TEST(SurfaceDistanceTest, ADegenerateTriangleGivesItsNearestCorner) {
  const Eigen::Vector3d a(0, 0, 0), b(1, 0, 0);
  const Eigen::Vector3d w = closest_point_weights(Eigen::Vector3d(0.9, 0.3, 0.0), a, b, b);
  EXPECT_TRUE(w.allFinite());
  EXPECT_NEAR((w[0] * a + (w[1] + w[2]) * b - Eigen::Vector3d(0.9, 0.0, 0.0)).norm(), 0.0, 1e-15);
}

TEST(SurfaceDistanceTest, SearchAgreesWithTryingEveryTriangleOnTheLiver) {
  const Scenario liver = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/liver.json");
  const BoundarySurface surface = boundary_surface(liver.mesh);
  Eigen::VectorXd positions(3 * static_cast<Eigen::Index>(surface.nodes.size()));
  for (std::size_t i = 0; i < surface.nodes.size(); ++i)
    positions.segment<3>(3 * static_cast<Eigen::Index>(i)) = liver.mesh.nodes[static_cast<std::size_t>(surface.nodes[i])];
  const SurfaceSearch search(positions, surface.triangles);
  std::mt19937_64 random(5);
  std::uniform_real_distribution<double> coordinate(0.0, 0.6);
  for (int q = 0; q < 300; ++q) {
    const Eigen::Vector3d p(coordinate(random), coordinate(random), coordinate(random));
    double brute = std::numeric_limits<double>::infinity();
    for (const std::array<int, 3>& t : surface.triangles) {
      const Eigen::Vector3d a = positions.segment<3>(3 * t[0]), b = positions.segment<3>(3 * t[1]),
                            c = positions.segment<3>(3 * t[2]);
      const Eigen::Vector3d w = closest_point_weights(p, a, b, c);
      brute = std::min(brute, (w[0] * a + w[1] * b + w[2] * c - p).norm());
    }
    const SurfacePoint found = search.closest(p);
    ASSERT_GE(found.triangle, 0);
    EXPECT_NEAR(found.distance, brute, 1e-15) << "query " << q;
    const std::array<int, 3>& t = surface.triangles[static_cast<std::size_t>(found.triangle)];
    const Eigen::Vector3d x = found.weights[0] * positions.segment<3>(3 * t[0]) +
                              found.weights[1] * positions.segment<3>(3 * t[1]) +
                              found.weights[2] * positions.segment<3>(3 * t[2]);
    EXPECT_NEAR((x - p).norm(), found.distance, 1e-15);
  }
}

}  // namespace
}  // namespace sigmafem
