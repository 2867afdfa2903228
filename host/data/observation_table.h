// ObservationTable: the data the filter reads (docs/FORMATS.md, "Observations"): per time
// step the SO position and the measured positions of the scenario's observed nodes.
// A missing value (not observed at that step) is NaN in memory and an empty field in the file.
// A tracker's frames at their own times (issue 15, item 3): an optional `frame_time` column
// after `time` says when the row's points were taken, inside the row's step ((t - dt, t]);
// filter/timed_observation.h observes them then.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace sigmafem {

struct ObservationTable {
  std::vector<std::string> comments;   // written as "# ..." lines before the header
  std::vector<int> steps;              // consecutive from 0
  std::vector<double> times;           // steps[k] * dt
  Eigen::MatrixX3d so;                 // SO position per row
  Eigen::MatrixXd points;              // row k: p0_x p0_y p0_z p1_x ... (NaN = missing)
  // With the frame_time column (else empty): per row, when its points were taken (NaN: no
  // frame in the row), and the share of the row's step at that time, in (0, 1] (1 without a
  // frame, or at the step's end).
  std::vector<double> frame_times;
  std::vector<double> frame_shares;

  int row_count() const { return static_cast<int>(steps.size()); }
  int point_count() const { return static_cast<int>(points.cols() / 3); }
};

// Reads an observations file and checks it against the scenario: `point_count` observed
// points, rows consecutive from step 0, each time equal to step * dt. Throws InputError
// naming the file, the line and the column for a header that does not match, a field that is
// not a number, a NaN or infinity written out, a missing SO value, a wrong field count, rows
// out of order, a time off the step grid, or a frame_time outside its row's step (a row
// with points and no frame_time is taken at the step's end). Empty point fields are kept as
// NaN (missing).
ObservationTable read_observations_csv(const std::string& path, int point_count, double dt);

// The header columns of an observations file with `point_count` points (and frame_time).
std::vector<std::string> observation_columns(int point_count, bool frame_time = false);

// The CSV text of the table (header "step,time,so_x,so_y,so_z,p0_x,...", with frame_time after
// time when the table has frame times).
std::string format_observations_csv(const ObservationTable& table);

}  // namespace sigmafem
