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

// The CSV text of the table (header "step,time,so_x,so_y,so_z,p0_x,...").
std::string format_observations_csv(const ObservationTable& table);

// Truth (docs/FORMATS.md): "step,time,<names...>" with each ligament's stiffness per step.
std::string format_truth_csv(const std::vector<std::string>& comments,
                             const std::vector<std::string>& names, const std::vector<int>& steps,
                             const std::vector<double>& times,
                             const std::vector<std::vector<double>>& stiffness);

}  // namespace sigmafem
