// PointCloudObservation (filter/point_cloud_observation.h) on the unit tetrahedron's surface:
// a measured point on the surface is observed at distance 0, one off it at its signed distance
// (the innovation positive outside); a triangle's row is the sum of its points' distances over
// sqrt(their count), a triangle without points has no row; each sigma point's surface moves
// its own observation by its displacement along the normal; the outlier gate leaves a point
// out before the binning, not its triangle; bad frames are refused.
#include "filter/point_cloud_observation.h"

#include <gtest/gtest.h>

#include <algorithm>
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

// The rows the last prediction made (the triangles the frame's points fell on).
std::vector<Eigen::Index> predicted_rows(const PointCloudObservation& cloud) {
  std::vector<Eigen::Index> rows;
  for (Eigen::Index t = 0; t < cloud.observation_count(); ++t)
    if (cloud.predicts_row(t)) rows.push_back(t);
  return rows;
}

// h for a frame of the one point p: its triangle's row.
Eigen::VectorXd observe_one(PointCloudObservation& cloud, const Eigen::Vector3d& p) {
  cloud.set_frame(p);
  Eigen::MatrixXd h;
  cloud.predicted_observations(h);
  const std::vector<Eigen::Index> rows = predicted_rows(cloud);
  EXPECT_EQ(rows.size(), 1u);
  return rows.empty() ? Eigen::VectorXd() : Eigen::VectorXd(h.row(rows[0]).transpose());
}

TEST(PointCloudObservationTest, ObservesTheSignedDistanceToTheSurface) {
  const BoundarySurface surface = boundary_surface(unit_tetrahedron());
  PointCloudObservation cloud(std::make_unique<FixedSurface>(tetrahedron_positions(surface, 2)), surface.triangles);
  EXPECT_EQ(cloud.observation_count(), 4) << "one row per surface triangle";
  // h = n . (x - p): the innovation 0 - h is the distance, positive outside.
  EXPECT_NEAR(observe_one(cloud, kCentroid)[0], 0.0, 1e-15);                              // on the surface
  EXPECT_NEAR(-observe_one(cloud, kCentroid + 2e-3 * kNormal)[0], 2e-3, 1e-15);           // 2 mm outside
  EXPECT_NEAR(-observe_one(cloud, kCentroid - 1e-3 * kNormal)[0], -1e-3, 1e-15);          // 1 mm inside
  const Eigen::VectorXd below = observe_one(cloud, Eigen::Vector3d(0.25, 0.25, -3e-3));   // 3 mm below z = 0
  EXPECT_NEAR(-below[0], 3e-3, 1e-15);
  EXPECT_EQ(below[0], below[1]) << "equal sigma points, equal observations";
}

// A triangle's row is sqrt(n) times its points' mean distance: the variance of one point's.
TEST(PointCloudObservationTest, BinsThePointsOfEachTriangle) {
  const BoundarySurface surface = boundary_surface(unit_tetrahedron());
  PointCloudObservation cloud(std::make_unique<FixedSurface>(tetrahedron_positions(surface, 1)), surface.triangles);
  Eigen::Matrix3Xd frame(3, 4);
  frame.col(0) = kCentroid + 2e-3 * kNormal;
  frame.col(1) = Eigen::Vector3d(0.5, 0.25, 0.25) - 1e-3 * kNormal;
  frame.col(2) = Eigen::Vector3d(0.25, 0.5, 0.25) + 0.5e-3 * kNormal;
  frame.col(3) = Eigen::Vector3d(0.25, 0.25, -3e-3);
  cloud.set_frame(frame);
  Eigen::MatrixXd h;
  cloud.predicted_observations(h);
  const std::vector<Eigen::Index> rows = predicted_rows(cloud);
  ASSERT_EQ(rows.size(), 2u) << "the slanted face and the bottom";
  Eigen::VectorXd values(2);
  values << h(rows[0], 0), h(rows[1], 0);
  std::sort(values.data(), values.data() + 2);
  EXPECT_NEAR(values[0], -3e-3, 1e-15) << "the bottom's one point, 3 mm outside";
  EXPECT_NEAR(values[1], -1.5e-3 / std::sqrt(3.0), 1e-15) << "the slanted face's (-2 + 1 - 0.5) mm over sqrt 3";
}

// The gate takes the one point 1 cm off out of its triangle's row and keeps the others.
TEST(PointCloudObservationTest, TheOutlierGateLeavesOutAPointNotItsTriangle) {
  const BoundarySurface surface = boundary_surface(unit_tetrahedron());
  PointCloudOptions options;
  options.observation_std = 1e-3;
  options.outlier_gate.enabled = true;
  PointCloudObservation cloud(std::make_unique<FixedSurface>(tetrahedron_positions(surface, 1)), surface.triangles,
                              options);
  Eigen::Matrix3Xd frame(3, 4);
  frame.col(0) = kCentroid + 1e-3 * kNormal;
  frame.col(1) = Eigen::Vector3d(0.5, 0.25, 0.25) - 1e-3 * kNormal;
  frame.col(2) = Eigen::Vector3d(0.25, 0.5, 0.25) + 10e-3 * kNormal;   // 1 cm off
  frame.col(3) = Eigen::Vector3d(0.25, 0.25, 0.5e-3);
  cloud.set_frame(frame);
  Eigen::MatrixXd h;
  cloud.predicted_observations(h);
  EXPECT_EQ(cloud.rejected_points(), std::vector<int>{2});
  const std::vector<Eigen::Index> rows = predicted_rows(cloud);
  ASSERT_EQ(rows.size(), 2u);
  for (Eigen::Index t : rows) EXPECT_LT(std::abs(h(t, 0)), 1e-3) << "the outlier is in no row";
}

TEST(PointCloudObservationTest, EachSigmaPointMovesItsObservationByItsOwnDisplacementAlongTheNormal) {
  const BoundarySurface surface = boundary_surface(unit_tetrahedron());
  Eigen::MatrixXd positions = tetrahedron_positions(surface, 3);
  const Eigen::Vector3d shift(0.4e-3, -0.1e-3, 0.3e-3);   // sigma point 1 moves rigidly
  for (Eigen::Index i = 0; i < positions.rows(); i += 3) positions.col(1).segment<3>(i) += shift;
  PointCloudObservation cloud(std::make_unique<FixedSurface>(positions), surface.triangles);
  const Eigen::VectorXd h = observe_one(cloud, kCentroid + 1e-3 * kNormal);
  EXPECT_NEAR(h[1] - h[0], kNormal.dot(shift), 1e-15);
  EXPECT_NEAR(h[2], h[0], 1e-15);
}

// A point taken 40% into a step in which the organ moves 1 mm along z is observed on the
// surface where it was then, not where it is at the step's end.
TEST(PointCloudObservationTest, APointTakenInsideAStepIsObservedOnTheSurfaceOfItsTime) {
  const BoundarySurface surface = boundary_surface(unit_tetrahedron());
  // One point on the face z = 0 at 40% of the step, taken then, or taken as at the step's end.
  const auto observe = [&](const Eigen::Vector3d& p, double share) {
    PointCloudObservation cloud(std::make_unique<MovingSurface>(tetrahedron_positions(surface, 2),
                                                                Eigen::Vector3d(0.0, 0.0, 1e-3)),
                                surface.triangles);
    cloud.set_frame(p, Eigen::VectorXd::Constant(1, share));
    cloud.advance(Eigen::Vector3d::Zero());
    Eigen::MatrixXd h;
    cloud.predicted_observations(h);
    const std::vector<Eigen::Index> rows = predicted_rows(cloud);
    EXPECT_EQ(rows.size(), 1u);
    return rows.empty() ? NAN : h(rows[0], 0);
  };
  EXPECT_NEAR(observe(Eigen::Vector3d(0.25, 0.25, 0.4e-3), 0.4), 0.0, 1e-15);
  EXPECT_NEAR(observe(Eigen::Vector3d(0.25, 0.25, 1e-3), 1.0), 0.0, 1e-15);   // on it at the step's end
  // Taken as at the step's end, the first point would lie 0.6 mm outside (below) the face,
  // now at z = 1 mm: h = n . (x - p) = -0.6 mm with n = -z.
  EXPECT_NEAR(observe(Eigen::Vector3d(0.25, 0.25, 0.4e-3), 1.0), -0.6e-3, 1e-15);
  // Asked before the step is made: the surface as it is (nothing to interpolate from).
  PointCloudObservation before(std::make_unique<MovingSurface>(tetrahedron_positions(surface, 2),
                                                               Eigen::Vector3d(0.0, 0.0, 1e-3)),
                               surface.triangles);
  before.set_frame(Eigen::Vector3d(0.25, 0.25, 0.4e-3), Eigen::VectorXd::Constant(1, 0.4));
  Eigen::MatrixXd h;
  before.predicted_observations(h);
  EXPECT_EQ(predicted_rows(before).size(), 1u);
}

TEST(PointCloudObservationTest, AnEmptyFrameObservesNothingAndBadInputIsRefused) {
  const BoundarySurface surface = boundary_surface(unit_tetrahedron());
  PointCloudObservation cloud(std::make_unique<FixedSurface>(tetrahedron_positions(surface, 2)), surface.triangles);
  Eigen::MatrixXd h;
  cloud.set_frame(Eigen::Matrix3Xd(3, 0));
  cloud.predicted_observations(h);
  EXPECT_TRUE(predicted_rows(cloud).empty());
  EXPECT_THROW(cloud.set_frame(Eigen::Matrix3Xd::Zero(3, 2), Eigen::Vector2d(0.5, 0.0)), std::invalid_argument)
      << "a share of 0 is the step before's end";
  EXPECT_THROW(cloud.set_frame(Eigen::Matrix3Xd::Zero(3, 2), Eigen::Vector3d::Ones()), std::invalid_argument);
  std::vector<std::array<int, 3>> bad = surface.triangles;
  bad[0][1] = 4;   // the tetrahedron has 4 surface nodes: 0..3
  EXPECT_THROW(PointCloudObservation(std::make_unique<FixedSurface>(tetrahedron_positions(surface, 2)), bad),
               std::invalid_argument);
}

}  // namespace
}  // namespace sigmafem
