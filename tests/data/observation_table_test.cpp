// The observations file: what is written reads back, and a file that does not match the
// scenario is rejected with the file, the line and the column in the message.
#include "temp_path.h"
#include "host/data/observation_table.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "host/common/input_error.h"

namespace sigmafem {
namespace {
namespace fs = std::filesystem;

class ObservationTableTest : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = test::unique_temp_path("sigmafem_observation_table_test").string() + ".csv";
    table_.comments = {"scenario test"};
    for (int k = 0; k < 3; ++k) {
      table_.steps.push_back(k);
      table_.times.push_back(0.01 * k);
    }
    table_.so = Eigen::MatrixX3d::Random(3, 3);
    table_.points = Eigen::MatrixXd::Random(3, 6);
    table_.points(1, 4) = NAN;   // point 1, y, not observed at step 1
  }
  void TearDown() override { fs::remove(path_); }

  void write(const std::string& text) { std::ofstream(path_) << text; }
  std::string good_text() const { return format_observations_csv(table_); }

  // The reader must reject `text` with a message containing each of `parts`.
  void expect_rejected(const std::string& text, const std::vector<std::string>& parts) {
    write(text);
    try {
      read_observations_csv(path_.string(), 2, 0.01);
      FAIL() << "accepted:\n" << text;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(path_.string()), std::string::npos) << message;
      for (const std::string& part : parts)
        EXPECT_NE(message.find(part), std::string::npos) << "'" << part << "' in: " << message;
    }
  }

  fs::path path_;
  ObservationTable table_;
};

TEST_F(ObservationTableTest, WrittenTableReadsBackWithMissingValues) {
  write(good_text());
  ObservationTable read = read_observations_csv(path_.string(), 2, 0.01);
  ASSERT_EQ(read.row_count(), 3);
  EXPECT_EQ(read.comments, table_.comments);
  // format_number keeps 10 significant digits.
  EXPECT_LT((read.so - table_.so).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_TRUE(std::isnan(read.points(1, 4))) << "an empty field is a missing value";
  read.points(1, 4) = 0.0;
  Eigen::MatrixXd expected = table_.points;
  expected(1, 4) = 0.0;
  EXPECT_LT((read.points - expected).cwiseAbs().maxCoeff(), 1e-9);
}

// Frames at their own times (issue 15, item 3): the frame_time column reads back, with each
// row's share of its step; a row without a frame is empty there (taken as at the step's end).
TEST_F(ObservationTableTest, FrameTimesReadBackWithTheirShareOfTheStep) {
  table_.frame_times = {0.0, 0.006, NAN};
  write(good_text());
  ASSERT_NE(good_text().find("step,time,frame_time,so_x"), std::string::npos);
  const ObservationTable read = read_observations_csv(path_.string(), 2, 0.01);
  ASSERT_EQ(read.frame_times.size(), 3u);
  EXPECT_EQ(read.frame_times[1], 0.006);
  EXPECT_TRUE(std::isnan(read.frame_times[2]));
  ASSERT_EQ(read.frame_shares.size(), 3u);
  EXPECT_NEAR(read.frame_shares[1], 0.6, 1e-12) << "0.006 s is 60% into the step (0, 0.01]";
  EXPECT_EQ(read.frame_shares[2], 1.0);
  EXPECT_LT((read.so - table_.so).cwiseAbs().maxCoeff(), 1e-9) << "the columns after frame_time shift right";
  // Without the column: no frame times.
  table_.frame_times.clear();
  write(good_text());
  EXPECT_TRUE(read_observations_csv(path_.string(), 2, 0.01).frame_times.empty());
}

TEST_F(ObservationTableTest, RejectsAFrameTimeOutsideItsStep) {
  table_.frame_times = {0.0, 0.0, 0.02};   // row 1's step is (0, 0.01]
  expect_rejected(good_text(), {"line 4", "frame_time 0", "outside the row's step", "(0, 0.01]"});
  table_.frame_times = {0.003, 0.01, 0.02};
  expect_rejected(good_text(), {"line 3", "rest state"});
}

TEST_F(ObservationTableTest, RejectsColumnsThatDoNotMatchTheScenario) {
  table_.points = Eigen::MatrixXd::Random(3, 9);   // three points, the scenario has two
  expect_rejected(good_text(), {"line 2", "header does not match", "2 observed points"});
}

TEST_F(ObservationTableTest, RejectsNonNumericField) {
  std::string text = good_text();
  text.replace(text.rfind('\n', text.size() - 2) + 1, 1, "x");   // last row's step
  expect_rejected(text, {"line 5", "column step", "not a finite number"});
}

TEST_F(ObservationTableTest, RejectsNaNWrittenOut) {
  table_.points(2, 0) = 1.0;
  std::string text = good_text();
  const std::size_t last_row = text.rfind('\n', text.size() - 2) + 1;
  const std::size_t sixth_comma = [&] {
    std::size_t at = last_row;
    for (int c = 0; c < 5; ++c) at = text.find(',', at) + 1;
    return at;
  }();
  text.replace(sixth_comma, text.find(',', sixth_comma) - sixth_comma, "nan");
  expect_rejected(text, {"line 5", "column p0_x", "nan"});
}

TEST_F(ObservationTableTest, RejectsRowsOutOfOrder) {
  std::swap(table_.steps[1], table_.steps[2]);
  expect_rejected(good_text(), {"line 4", "out of order", "expected 1"});
}

TEST_F(ObservationTableTest, RejectsTimesOffTheStepGrid) {
  table_.times[2] = 0.025;
  expect_rejected(good_text(), {"line 5", "time 0.025", "step * dt"});
}

TEST_F(ObservationTableTest, RejectsMissingSoPosition) {
  table_.so(1, 2) = NAN;
  std::string text = good_text();
  // format writes NaN SO values as "nan"; an empty SO field is the other way to be missing.
  const std::size_t at = text.find("nan");
  ASSERT_NE(at, std::string::npos);
  text.erase(at, 3);
  expect_rejected(text, {"line 4", "column so_z", "empty"});
}

TEST_F(ObservationTableTest, RejectsMissingFileAndEmptyFile) {
  EXPECT_THROW(read_observations_csv((path_.string() + ".absent"), 2, 0.01), InputError);
  expect_rejected("", {"empty file"});
  expect_rejected("step,time,so_x,so_y,so_z,p0_x,p0_y,p0_z,p1_x,p1_y,p1_z\n", {"no data rows"});
}

}  // namespace
}  // namespace sigmafem
