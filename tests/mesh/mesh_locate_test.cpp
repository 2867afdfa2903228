// Point location and barycentric interpolation: a linear field is reproduced exactly at any
// point of the body (linear tetrahedra interpolate linear fields exactly), at nodes bit for
// bit, on faces, and just outside the mesh at the nearest point of the surface.
#include "host/mesh/mesh_locate.h"

#include <gtest/gtest.h>

#include <random>
#include <string>

#include "host/mesh/mesh.h"
#include "host/mesh/observed_points.h"

namespace sigmafem {
namespace {

class MeshLocateTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // The 30 x 15 x 15 cm box, about 400 tetrahedra: its surface is planar, so the mesh fills
    // the box exactly.
    mesh_ = read_mesh(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box_coarse.msh");
    orient_and_check(mesh_, "box_coarse.msh");
    field_.resize(3 * mesh_.node_count());
    for (int i = 0; i < mesh_.node_count(); ++i) field_.segment<3>(3 * i) = linear(mesh_.nodes[i]);
  }

  // A linear (affine) field with all nine gradient terms nonzero.
  static Eigen::Vector3d linear(const Eigen::Vector3d& p) {
    Eigen::Matrix3d a;
    a << 1.5, -0.25, 0.75, 0.5, 2.0, -1.0, -0.3, 0.9, 1.1;
    return a * p + Eigen::Vector3d(0.01, -0.02, 0.03);
  }

  void expect_valid_weights(const MeshLocation& location, const std::string& what) {
    ASSERT_GE(location.tetrahedron, 0) << what;
    double sum = 0.0;
    for (double w : location.weights) {
      EXPECT_GE(w, 0.0) << what << ": weights are clamped to >= 0";
      sum += w;
    }
    EXPECT_NEAR(sum, 1.0, 1e-14) << what << ": weights sum to 1";
  }

  Mesh mesh_;
  Eigen::VectorXd field_;
};

TEST_F(MeshLocateTest, LinearFieldIsReproducedAtInteriorPoints) {
  std::mt19937 random(5);
  std::uniform_real_distribution<double> unit(0.01, 0.99);
  for (int n = 0; n < 200; ++n) {
    const Eigen::Vector3d p(0.30 * unit(random), 0.15 * unit(random), 0.15 * unit(random));
    const MeshLocation location = locate_point(mesh_, p);
    expect_valid_weights(location, "interior point " + std::to_string(n));
    EXPECT_EQ(location.outside_distance, 0.0) << "an interior point is inside";
    EXPECT_LT((ObservedPoint::at(mesh_, location).of(field_) - linear(p)).norm(), 1e-13)
        << "a linear field is interpolated exactly at point " << n;
  }
}

TEST_F(MeshLocateTest, NodesInterpolateToTheirValueBitForBit) {
  for (int i = 0; i < mesh_.node_count(); i += 7) {
    const MeshLocation location = locate_point(mesh_, mesh_.nodes[i]);
    const Eigen::Vector3d value = ObservedPoint::at(mesh_, location).of(field_);
    EXPECT_EQ(value, Eigen::Vector3d(field_.segment<3>(3 * i))) << "node " << i;
  }
}

TEST_F(MeshLocateTest, PointsOnFacesAreInside) {
  // Centroids of the faces of some tetrahedra: shared interior faces and boundary faces.
  for (int e = 0; e < mesh_.tetrahedron_count(); e += 13) {
    const auto& t = mesh_.tetrahedra[e];
    for (int skip = 0; skip < 4; ++skip) {
      Eigen::Vector3d p = Eigen::Vector3d::Zero();
      for (int k = 0; k < 4; ++k)
        if (k != skip) p += mesh_.nodes[t[k]] / 3.0;
      const MeshLocation location = locate_point(mesh_, p);
      expect_valid_weights(location, "face point");
      EXPECT_EQ(location.outside_distance, 0.0) << "a face point of element " << e << " is inside";
      EXPECT_LT((ObservedPoint::at(mesh_, location).of(field_) - linear(p)).norm(), 1e-13);
    }
  }
  // On an edge of the box and on its boundary faces.
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.1234, 0.0, 0.0), Eigen::Vector3d(0.2, 0.07, 0.15),
                                   Eigen::Vector3d(0.3, 0.11, 0.04)}) {
    const MeshLocation location = locate_point(mesh_, p);
    expect_valid_weights(location, "boundary point");
    EXPECT_EQ(location.outside_distance, 0.0) << "a point on the surface is inside";
    EXPECT_LT((ObservedPoint::at(mesh_, location).of(field_) - linear(p)).norm(), 1e-13);
  }
}

TEST_F(MeshLocateTest, PointJustOutsideGoesToTheNearestSurfacePoint) {
  const Eigen::Vector3d surface(0.137, 0.061, 0.15);      // on the top face z = 0.15
  const Eigen::Vector3d outside = surface + Eigen::Vector3d(0.0, 0.0, 2e-4);
  const MeshLocation location = locate_point(mesh_, outside);
  expect_valid_weights(location, "outside point");
  EXPECT_NEAR(location.outside_distance, 2e-4, 1e-12) << "the distance to the top face";
  EXPECT_LT((ObservedPoint::at(mesh_, location).of(field_) - linear(surface)).norm(), 1e-12)
      << "clamped weights give the nearest point of the surface";

  // Beyond a corner the nearest point is the corner.
  const Eigen::Vector3d corner(0.3, 0.15, 0.15);
  const MeshLocation beyond = locate_point(mesh_, corner + Eigen::Vector3d(1e-3, 1e-3, 1e-3));
  expect_valid_weights(beyond, "beyond a corner");
  EXPECT_NEAR(beyond.outside_distance, std::sqrt(3.0) * 1e-3, 1e-12);
  EXPECT_LT((ObservedPoint::at(mesh_, beyond).of(field_) - linear(corner)).norm(), 1e-12);
}

}  // namespace
}  // namespace sigmafem
