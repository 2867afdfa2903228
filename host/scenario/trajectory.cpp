// Trajectory: the solid object's (SO) position over time, so(t), and the reader for the
// trajectory CSV files that `"type": "file"` points to (docs/FORMATS.md). Positions are
// in metres, absolute (the same frame as the transformed mesh), times in seconds.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "host/common/input_error.h"
#include "host/common/physical_limits.h"
#include "host/data/csv_fields.h"
#include "host/data/csv_format.h"
#include "host/scenario/scenario.h"

namespace sigmafem {

Eigen::Vector3d Trajectory::position(double t, const Eigen::Vector3d& start) const {
  if (type == Type::linear) return start + velocity * t;
  // load_scenario() and read_trajectory_csv() guarantee at least one knot; a default
  // constructed waypoint trajectory without knots stays put rather than reading past the end.
  if (times.empty()) return start;
  // Held outside the knots: before the first the SO waits where the record starts, after
  // the last it stays where the hand stopped.
  if (t <= times.front()) return positions.front();
  if (t >= times.back()) return positions.back();
  // First knot strictly after t; t == times[i] gives the segment [i, i + 1] with weight 0,
  // so a knot's position comes back bit-exact.
  const auto after = std::upper_bound(times.begin(), times.end(), t);
  const size_t i1 = static_cast<size_t>(after - times.begin());
  const size_t i0 = i1 - 1;
  const double w = (t - times[i0]) / (times[i1] - times[i0]);
  return positions[i0] + w * (positions[i1] - positions[i0]);
}


Trajectory read_trajectory_csv(const std::string& path) {
  static const char* const kColumns[] = {"time", "x", "y", "z"};
  Trajectory trajectory;
  trajectory.type = Trajectory::Type::file;
  trajectory.file = path;
  auto on_line = [&](const std::vector<std::string>& fields, const std::string& at, bool is_header) {
    if (is_header) {
      // The header is required: without it a file of x,y,z,time columns would load silently.
      if (fields != std::vector<std::string>(std::begin(kColumns), std::end(kColumns)))
        throw InputError(at + "expected the header \"time,x,y,z\", found " +
                         std::to_string(fields.size()) + " columns starting \"" +
                         (fields.empty() ? std::string() : fields[0]) + "\"");
      return;
    }
    if (fields.size() != 4)
      throw InputError(at + "expected 4 comma-separated numbers (time,x,y,z), found " +
                       std::to_string(fields.size()) + " fields");
    double values[4];
    for (size_t k = 0; k < 4; ++k) {
      if (!parse_double(fields[k], values[k]))
        throw InputError(at + "column " + kColumns[k] + " is not a finite number: \"" + fields[k] +
                         "\"");
      const double bound = k == 0 ? kMaxScenarioMagnitude : kMaxPositionMagnitude;
      if (std::fabs(values[k]) > bound)
        throw InputError(at + "column " + kColumns[k] + " is " + fields[k] + ", beyond +-" +
                         format_number(bound) + (k == 0 ? " s" : " m; positions are in metres"));
    }
    if (!trajectory.times.empty() && !(values[0] > trajectory.times.back())) {
      std::ostringstream what;
      what << "time " << values[0] << " does not come after the previous row's time "
           << trajectory.times.back() << "; times must strictly increase";
      throw InputError(at + what.str());
    }
    trajectory.times.push_back(values[0]);
    trajectory.positions.emplace_back(values[1], values[2], values[3]);
  };
  read_csv_file(path, "trajectory CSV " + path, on_line);
  return trajectory;
}

}  // namespace sigmafem
