// PointCloudObservation (filter/point_cloud_observation.h) on the unit tetrahedron's surface:
// a measured point on the surface is observed at distance 0, one off it at its signed distance
// (the innovation positive outside); each sigma point's surface moves its own observation by
// its displacement along the normal; rows beyond the frame are 0; bad frames are refused.
#include "filter/point_cloud_observation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "host/mesh/mesh.h"
#include "mesh/unit_tetrahedron.h"

namespace sigmafem {
namespace {

// An ensemble whose sigma points hold given surface node positions (3n x S) and do not move.
class FixedSurface : public Ensemble {
 public:
  explicit FixedSurface(Eigen::MatrixXd positions) : positions_(std::move(positions)) {}
  int sigma_count() const override { return static_cast<int>(positions_.cols()); }
  int parameter_count() const override { return 1; }
  int observation_count() const override { return static_cast<int>(positions_.rows()); }
  void set_parameters(const Eigen::MatrixXd&) override {}
  StepReport advance(const Eigen::Vector3d&) override { return {}; }
  void predicted_observations(Eigen::MatrixXd& y) const override { y = positions_; }
  void recenter(const Recentering&) override {}

 private:
  Eigen::MatrixXd positions_;
};

// A FixedSurface whose every sigma point moves by `velocity` in each advance.
class MovingSurface : public FixedSurface {
 public:
  MovingSurface(Eigen::MatrixXd positions, const Eigen::Vector3d& velocity)
      : FixedSurface(positions), positions_(std::move(positions)), velocity_(velocity) {}
  StepReport advance(const Eigen::Vector3d&) override {
    for (Eigen::Index i = 0; i < positions_.rows(); i += 3) positions_.middleRows(i, 3).colwise() += velocity_;
    return {};
  }
  void predicted_observations(Eigen::MatrixXd& y) const override { y = positions_; }

 private:
  Eigen::MatrixXd positions_;
  Eigen::Vector3d velocity_;
};

// The unit tetrahedron's surface nodes, the same for `S` sigma points.
Eigen::MatrixXd tetrahedron_positions(const BoundarySurface& surface, int S) {
  const Mesh mesh = unit_tetrahedron();
  Eigen::VectorXd x(3 * static_cast<Eigen::Index>(surface.nodes.size()));
  for (std::size_t i = 0; i < surface.nodes.size(); ++i)
    x.segment<3>(3 * static_cast<Eigen::Index>(i)) = mesh.nodes[static_cast<std::size_t>(surface.nodes[i])];
  return x.replicate(1, S);
}

// The slanted face x + y + z = 1 has the outward normal (1, 1, 1) / sqrt 3; its centroid.
const Eigen::Vector3d kNormal = Eigen::Vector3d::Ones().normalized();
const Eigen::Vector3d kCentroid = Eigen::Vector3d::Constant(1.0 / 3.0);

TEST(PointCloudObservationTest, ObservesTheSignedDistanceToTheSurface) {
  const BoundarySurface surface = boundary_surface(unit_tetrahedron());
  PointCloudObservation cloud(std::make_unique<FixedSurface>(tetrahedron_positions(surface, 2)), surface.triangles, 5);
  EXPECT_EQ(cloud.observation_count(), 5);
  Eigen::Matrix3Xd frame(3, 4);
  frame.col(0) = kCentroid;                                    // on the surface
  frame.col(1) = kCentroid + 2e-3 * kNormal;                  // 2 mm outside
  frame.col(2) = kCentroid - 1e-3 * kNormal;                  // 1 mm inside
  frame.col(3) = Eigen::Vector3d(0.25, 0.25, -3e-3);          // 3 mm below the face z = 0
  cloud.set_frame(frame);
  Eigen::MatrixXd h;
  cloud.predicted_observations(h);
  ASSERT_EQ(h.rows(), 5);
  ASSERT_EQ(h.cols(), 2);
  // h = n . (x - p): the innovation 0 - h is the distance, positive outside.
  EXPECT_NEAR(h(0, 0), 0.0, 1e-15);
  EXPECT_NEAR(-h(1, 0), 2e-3, 1e-15);
  EXPECT_NEAR(-h(2, 0), -1e-3, 1e-15);
  EXPECT_NEAR(-h(3, 0), 3e-3, 1e-15);
  EXPECT_EQ(h(4, 0), 0.0) << "a row beyond the frame";
  EXPECT_EQ(h.col(0), h.col(1)) << "equal sigma points, equal observations";
}

TEST(PointCloudObservationTest, EachSigmaPointMovesItsObservationByItsOwnDisplacementAlongTheNormal) {
  const BoundarySurface surface = boundary_surface(unit_tetrahedron());
  Eigen::MatrixXd positions = tetrahedron_positions(surface, 3);
  const Eigen::Vector3d shift(0.4e-3, -0.1e-3, 0.3e-3);   // sigma point 1 moves rigidly
  for (Eigen::Index i = 0; i < positions.rows(); i += 3) positions.col(1).segment<3>(i) += shift;
  PointCloudObservation cloud(std::make_unique<FixedSurface>(positions), surface.triangles, 1);
  cloud.set_frame(kCentroid + 1e-3 * kNormal);
  Eigen::MatrixXd h;
  cloud.predicted_observations(h);
  EXPECT_NEAR(h(0, 1) - h(0, 0), kNormal.dot(shift), 1e-15);
  EXPECT_NEAR(h(0, 2), h(0, 0), 1e-15);
}

// A point taken 40% into a step in which the organ moves 1 mm along z is observed on the
// surface where it was then, not where it is at the step's end.
TEST(PointCloudObservationTest, APointTakenInsideAStepIsObservedOnTheSurfaceOfItsTime) {
  const BoundarySurface surface = boundary_surface(unit_tetrahedron());
  PointCloudObservation cloud(std::make_unique<MovingSurface>(tetrahedron_positions(surface, 2),
                                                              Eigen::Vector3d(0.0, 0.0, 1e-3)),
                              surface.triangles, 2);
  Eigen::Matrix3Xd frame(3, 2);
  frame.col(0) = Eigen::Vector3d(0.25, 0.25, 0.4e-3);   // on the face z = 0 at 40% of the step
  frame.col(1) = Eigen::Vector3d(0.25, 0.25, 1e-3);     // on it at the step's end
  cloud.set_frame(frame, Eigen::Vector2d(0.4, 1.0));
  cloud.advance(Eigen::Vector3d::Zero());
  Eigen::MatrixXd h;
  cloud.predicted_observations(h);
  EXPECT_NEAR(h(0, 0), 0.0, 1e-15);
  EXPECT_NEAR(h(1, 0), 0.0, 1e-15);
  // Taken as at the step's end, the first point would lie 0.6 mm outside (below) the face,
  // now at z = 1 mm: h = n . (x - p) = -0.6 mm with n = -z.
  PointCloudObservation at_end(std::make_unique<MovingSurface>(tetrahedron_positions(surface, 2),
                                                               Eigen::Vector3d(0.0, 0.0, 1e-3)),
                               surface.triangles, 2);
  at_end.set_frame(frame);
  at_end.advance(Eigen::Vector3d::Zero());
  at_end.predicted_observations(h);
  EXPECT_NEAR(h(0, 0), -0.6e-3, 1e-15);
}

TEST(PointCloudObservationTest, AnEmptyFrameObservesNothingAndBadInputIsRefused) {
  const BoundarySurface surface = boundary_surface(unit_tetrahedron());
  PointCloudObservation cloud(std::make_unique<FixedSurface>(tetrahedron_positions(surface, 2)), surface.triangles, 2);
  Eigen::MatrixXd h;
  cloud.set_frame(Eigen::Matrix3Xd(3, 0));
  cloud.predicted_observations(h);
  EXPECT_TRUE(h.isZero());
  EXPECT_THROW(cloud.set_frame(Eigen::Matrix3Xd::Zero(3, 3)), std::invalid_argument) << "3 points, made for 2";
  EXPECT_THROW(cloud.set_frame(Eigen::Matrix3Xd::Zero(3, 2), Eigen::Vector2d(0.5, 0.0)), std::invalid_argument)
      << "a share of 0 is the step before's end";
  EXPECT_THROW(cloud.set_frame(Eigen::Matrix3Xd::Zero(3, 2), Eigen::Vector3d::Ones()), std::invalid_argument);
  std::vector<std::array<int, 3>> bad = surface.triangles;
  bad[0][1] = 4;   // the tetrahedron has 4 surface nodes: 0..3
  EXPECT_THROW(PointCloudObservation(std::make_unique<FixedSurface>(tetrahedron_positions(surface, 2)), bad, 2),
               std::invalid_argument);
}

}  // namespace
}  // namespace sigmafem
