// Tests for Trajectory (host/scenario/trajectory.cpp): so(t) for linear, waypoint and file
// trajectories, exact at and between knots and held outside them, and the CSV reader with
// its errors, which must name the file and the line.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <fstream>

#include "temp_path.h"
#include "host/common/input_error.h"
#include "host/scenario/scenario.h"

namespace sigmafem {
namespace {

namespace fs = std::filesystem;
using test::TempDir;


// Knots whose midpoints are exact in binary, so "between" can be compared with ==.
Trajectory three_waypoints() {
  Trajectory t;
  t.type = Trajectory::Type::waypoints;
  t.times = {1.0, 2.0, 4.0};
  t.positions = {Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(1.0, -2.0, 0.5),
                 Eigen::Vector3d(3.0, -2.0, 0.25)};
  return t;
}

const Eigen::Vector3d kStart(0.3, 0.075, 0.075);

TEST(TrajectoryTest, LinearIsStartPlusVelocityTimesTime) {
  Trajectory t;
  t.type = Trajectory::Type::linear;
  t.velocity = Eigen::Vector3d(0.004, 0.002, 0.001);
  EXPECT_EQ(t.position(0.0, kStart), kStart);
  EXPECT_EQ(t.position(15.0, kStart), kStart + Eigen::Vector3d(0.004, 0.002, 0.001) * 15.0);
  EXPECT_NEAR((t.position(7.5, kStart) - Eigen::Vector3d(0.33, 0.09, 0.0825)).norm(), 0.0, 1e-15);
}

TEST(TrajectoryTest, WaypointsAreExactAtTheKnots) {
  const Trajectory t = three_waypoints();
  for (size_t i = 0; i < t.times.size(); ++i) {
    EXPECT_EQ(t.position(t.times[i], kStart), t.positions[i]) << "knot " << i;
  }
}

TEST(TrajectoryTest, WaypointsAreLinearBetweenKnots) {
  const Trajectory t = three_waypoints();
  EXPECT_EQ(t.position(1.5, kStart), Eigen::Vector3d(0.5, -1.0, 0.25));
  EXPECT_EQ(t.position(1.25, kStart), Eigen::Vector3d(0.25, -0.5, 0.125));
  EXPECT_EQ(t.position(3.0, kStart), Eigen::Vector3d(2.0, -2.0, 0.375));
  EXPECT_EQ(t.position(3.5, kStart), Eigen::Vector3d(2.5, -2.0, 0.3125));
}

TEST(TrajectoryTest, WaypointsAreHeldBeforeTheFirstAndAfterTheLast) {
  const Trajectory t = three_waypoints();
  EXPECT_EQ(t.position(0.0, kStart), t.positions.front()) << "the start point is not used";
  EXPECT_EQ(t.position(-5.0, kStart), t.positions.front());
  EXPECT_EQ(t.position(4.5, kStart), t.positions.back());
  EXPECT_EQ(t.position(1e9, kStart), t.positions.back());
}

TEST(TrajectoryTest, OneWaypointIsAFixedPoint) {
  Trajectory t;
  t.type = Trajectory::Type::waypoints;
  t.times = {2.0};
  t.positions = {Eigen::Vector3d(1, 2, 3)};
  EXPECT_EQ(t.position(0.0, kStart), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(t.position(2.0, kStart), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(t.position(9.0, kStart), Eigen::Vector3d(1, 2, 3));
}

TEST(TrajectoryTest, FileReadsKnotsAndInterpolatesLikeWaypoints) {
  TempDir dir;
  const std::string file = dir.write("traj.csv",
                                     "# recorded by hand\n"
                                     "time,x,y,z\n"
                                     "0,0.25,0.5,0.125\n"
                                     "\n"
                                     "0.5, 0.75 ,0.5,0.125\r\n"
                                     "# a comment between rows\n"
                                     "2.5,0.75,1.5,-0.125\n");
  const Trajectory t = read_trajectory_csv(file);
  EXPECT_EQ(t.type, Trajectory::Type::file);
  EXPECT_EQ(t.file, file);
  ASSERT_EQ(t.times, (std::vector<double>{0.0, 0.5, 2.5}));
  EXPECT_EQ(t.position(0.0, kStart), Eigen::Vector3d(0.25, 0.5, 0.125));
  EXPECT_EQ(t.position(0.5, kStart), Eigen::Vector3d(0.75, 0.5, 0.125));
  EXPECT_EQ(t.position(2.5, kStart), Eigen::Vector3d(0.75, 1.5, -0.125));
  EXPECT_EQ(t.position(0.25, kStart), Eigen::Vector3d(0.5, 0.5, 0.125));
  EXPECT_EQ(t.position(1.5, kStart), Eigen::Vector3d(0.75, 1.0, 0.0));
  EXPECT_EQ(t.position(30.0, kStart), Eigen::Vector3d(0.75, 1.5, -0.125));
}

// The message of read_trajectory_csv on `text`, or a failure if it accepted it.
std::string csv_error(const TempDir& dir, const std::string& text, std::string& file) {
  file = dir.write("bad.csv", text);
  try {
    read_trajectory_csv(file);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "read_trajectory_csv accepted:\n" << text;
  return "";
}

TEST(TrajectoryTest, MalformedCsvNamesFileAndLine) {
  TempDir dir;
  struct Case {
    const char* text;
    const char* expected;  // besides the file name
  };
  const Case cases[] = {
      {"", "empty file"},
      {"# only a comment\n", "empty file"},
      {"time,x,y,z\n", "no data rows"},
      {"0,1,2,3\n", "line 1: expected the header"},
      {"t,x,y,z\n0,1,2,3\n", "line 1: expected the header"},
      {"time,x,y,z\n0,1,2\n", "line 2: expected 4 comma-separated numbers"},
      {"time,x,y,z\n0,1,2,3,4\n", "line 2: expected 4"},
      {"time,x,y,z\n0,1,2,3,\n", "line 2: expected 4"},
      {"time,x,y,z\n0,1,2,3\n1,1,abc,3\n", "line 3: column y is not a finite number: \"abc\""},
      {"time,x,y,z\n0,1,,3\n", "line 2: column y"},
      {"time,x,y,z\n0,1,2,3x\n", "line 2: column z"},
      {"time,x,y,z\n0,1,2,nan\n", "line 2: column z"},
      {"time,x,y,z\n0,1,2,3\n\n# c\n0,1,2,3\n", "line 5: time 0 does not come after"},
      {"time,x,y,z\n1,1,2,3\n0.5,1,2,3\n", "line 3: time 0.5 does not come after"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    std::string file;
    const std::string message = csv_error(dir, c.text, file);
    EXPECT_NE(message.find("trajectory CSV " + file), std::string::npos) << message;
    EXPECT_NE(message.find(c.expected), std::string::npos) << message;
  }
}

TEST(TrajectoryTest, MissingCsvNamesTheFile) {
  try {
    read_trajectory_csv("/nonexistent/folder/traj.csv");
    FAIL() << "no error for a missing file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/folder/traj.csv"), std::string::npos);
  }
}

}  // namespace
}  // namespace sigmafem
