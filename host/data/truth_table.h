// TruthTable: each ligament's true stiffness per step (docs/FORMATS.md, "Truth"), written by
// the generator and read by `estimate` to compute the error figures.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace sigmafem {

struct TruthTable {
  std::vector<std::string> comments;
  std::vector<std::string> names;       // ligament names, in file order
  std::vector<int> steps;               // consecutive from 0
  std::vector<double> times;
  Eigen::MatrixXd stiffness;            // rows = steps, columns = names

  int column(const std::string& name) const;   // -1 if absent
};

std::string format_truth_csv(const TruthTable& table);

// Reads a truth file; throws InputError naming the file, line and column on any problem.
TruthTable read_truth_csv(const std::string& path);

}  // namespace sigmafem
