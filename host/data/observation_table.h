// ObservationTable: the data the filter reads (docs/FORMATS.md, "Observations"): per time
// step the SO position and the measured positions of the scenario's observed nodes.
// A missing value (not observed at that step) is NaN in memory and an empty field in the file.
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

  int row_count() const { return static_cast<int>(steps.size()); }
  int point_count() const { return static_cast<int>(points.cols() / 3); }
};

// Reads an observations file and checks it against the scenario: `point_count` observed
// points, rows consecutive from step 0, each time equal to step * dt. Throws InputError
// naming the file, the line and the column for a header that does not match, a field that is
// not a number, a NaN or infinity written out, a missing SO value, a wrong field count, rows
// out of order, or a time off the step grid. Empty point fields are kept as NaN (missing).
ObservationTable read_observations_csv(const std::string& path, int point_count, double dt);

// The header columns of an observations file with `point_count` points.
std::vector<std::string> observation_columns(int point_count);

// The CSV text of the table (header "step,time,so_x,so_y,so_z,p0_x,...").
std::string format_observations_csv(const ObservationTable& table);

}  // namespace sigmafem
