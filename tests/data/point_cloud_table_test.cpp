// The point-cloud file (host/data/point_cloud_table.h): what is written reads back frame by
// frame; frames go to the simulation step they were taken in, with their share of it; a bad file is refused naming the file,
// the line and what is wrong.
#include "host/data/point_cloud_table.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "host/common/input_error.h"
#include "temp_path.h"

namespace sigmafem {
namespace {

PointCloudTable two_frames() {
  PointCloudTable table;
  table.comments = {"test"};
  table.frames.push_back({0.0333, Eigen::Matrix3Xd::Random(3, 3) * 0.1});
  table.frames.push_back({0.0667, Eigen::Matrix3Xd::Random(3, 1) * 0.1});
  return table;
}

TEST(PointCloudTableTest, WrittenFramesReadBack) {
  const test::TempDir dir;
  const PointCloudTable table = two_frames();
  const PointCloudTable read = read_point_cloud_csv(dir.write("pointcloud.csv", format_point_cloud_csv(table)));
  EXPECT_EQ(read.comments, table.comments);
  ASSERT_EQ(read.frames.size(), 2u);
  EXPECT_EQ(read.point_count(), 4);
  EXPECT_EQ(read.max_frame_points(), 3);
  for (std::size_t f = 0; f < 2; ++f) {
    EXPECT_EQ(read.frames[f].time, table.frames[f].time);
    // format_number's 10 significant digits: 1e-11 m on these 0.1 m positions.
    EXPECT_LT((read.frames[f].points - table.frames[f].points).cwiseAbs().maxCoeff(), 1e-11);
  }
}

TEST(PointCloudTableTest, FramesGoToTheStepTheyWereTakenInWithTheirShareOfIt) {
  PointCloudTable table;
  table.frames.push_back({0.0, Eigen::Matrix3Xd::Zero(3, 2)});      // the rest state
  table.frames.push_back({0.0333, Eigen::Matrix3Xd::Random(3, 3)});  // in (0.03, 0.04]
  table.frames.push_back({0.05, Eigen::Matrix3Xd::Ones(3, 1)});      // on the grid
  table.frames.push_back({0.0649, Eigen::Matrix3Xd::Ones(3, 2)});    // two frames in (0.06, 0.07]
  table.frames.push_back({0.0667, Eigen::Matrix3Xd::Ones(3, 1)});
  const std::vector<StepFrames> by_step = frames_by_step(table, 0.01, 8, "cloud.csv");
  ASSERT_EQ(by_step.size(), 8u);
  EXPECT_EQ(by_step[0].points.cols(), 0) << "the rest state takes no frame";
  EXPECT_EQ(by_step[3].points.cols(), 0);
  ASSERT_EQ(by_step[4].points.cols(), 3);
  EXPECT_EQ(by_step[4].points, table.frames[1].points);
  EXPECT_NEAR(by_step[4].share[0], 0.33, 1e-9);
  ASSERT_EQ(by_step[5].points.cols(), 1);
  EXPECT_EQ(by_step[5].share[0], 1.0) << "a frame on the grid is at its step's end exactly";
  ASSERT_EQ(by_step[7].points.cols(), 3);
  EXPECT_NEAR(by_step[7].share[1], 0.49, 1e-9);
  EXPECT_NEAR(by_step[7].share[2], 0.67, 1e-9);
  EXPECT_THROW(frames_by_step(table, 0.01, 7, "cloud.csv"), InputError) << "0.0649 s lies in step 7 of 0..6";
}

TEST(PointCloudTableTest, BadFilesAreRefusedWithTheLineAndTheReason) {
  const test::TempDir dir;
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {"t,x,y,z\n0.1,0,0,0\n", {"line 1", "header must be time,x,y,z"}},
      {"time,x,y,z\n0.1,0,0\n", {"line 2", "expected 4 fields"}},
      {"time,x,y,z\n0.1,0,abc,0\n", {"line 2", "column y", "not a finite number"}},
      {"time,x,y,z\n0.1,0,,0\n", {"line 2", "column y", "empty"}},
      {"time,x,y,z\n0.1,0,0,5000\n", {"line 2", "column z", "metres"}},
      {"time,x,y,z\n-0.1,0,0,0\n", {"line 2", "negative"}},
      {"time,x,y,z\n0.2,0,0,0\n0.1,0,0,0\n", {"line 3", "comes before", "together"}},
      {"time,x,y,z\n", {"no"}},
  };
  for (const auto& [text, parts] : cases) {
    const std::string path = dir.write("bad.csv", text);
    try {
      read_point_cloud_csv(path);
      ADD_FAILURE() << "accepted:\n" << text;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path), std::string::npos) << message;
      for (const std::string& part : parts)
        EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' in: " << message;
    }
  }
}

}  // namespace
}  // namespace sigmafem
