#include "host/data/observation_table.h"

#include <cmath>
#include <sstream>

#include "host/data/csv_format.h"

namespace sigmafem {

std::string format_observations_csv(const ObservationTable& table) {
  std::ostringstream out;
  for (const std::string& comment : table.comments) out << "# " << comment << '\n';
  out << "step,time,so_x,so_y,so_z";
  for (int p = 0; p < table.point_count(); ++p)
    out << ",p" << p << "_x,p" << p << "_y,p" << p << "_z";
  out << '\n';
  for (int k = 0; k < table.row_count(); ++k) {
    out << table.steps[k] << ',' << format_number(table.times[k]);
    for (int a = 0; a < 3; ++a) out << ',' << format_number(table.so(k, a));
    for (Eigen::Index c = 0; c < table.points.cols(); ++c) {
      out << ',';
      if (!std::isnan(table.points(k, c))) out << format_number(table.points(k, c));
    }
    out << '\n';
  }
  return out.str();
}

std::string format_truth_csv(const std::vector<std::string>& comments,
                             const std::vector<std::string>& names, const std::vector<int>& steps,
                             const std::vector<double>& times,
                             const std::vector<std::vector<double>>& stiffness) {
  std::ostringstream out;
  for (const std::string& comment : comments) out << "# " << comment << '\n';
  out << "step,time";
  for (const std::string& name : names) out << ',' << name;
  out << '\n';
  for (std::size_t k = 0; k < steps.size(); ++k) {
    out << steps[k] << ',' << format_number(times[k]);
    for (double value : stiffness[k]) out << ',' << format_number(value);
    out << '\n';
  }
  return out.str();
}

}  // namespace sigmafem
