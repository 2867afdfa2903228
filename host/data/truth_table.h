// TruthTable: each ligament's true stiffness per step (docs/FORMATS.md, "Truth"), written by
// the generator and read by `estimate` to compute the error figures.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <ostream>
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

// truth.csv beside the observations is optional (measured data has none). When there but not
// usable with this data (malformed, a ligament column missing or not in the scenario, a row
// count other than the observations'), a warning on `warnings` says why and the run goes on
// without it: the figures it would give are left out rather than computed from a wrong truth.
std::optional<TruthTable> read_optional_truth_csv(const std::string& path,
                                                  const std::vector<std::string>& ligament_names,
                                                  int row_count, std::ostream& warnings);

}  // namespace sigmafem
