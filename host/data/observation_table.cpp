#include "host/data/observation_table.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "host/common/input_error.h"
#include "host/common/physical_limits.h"
#include "host/data/csv_fields.h"
#include "host/data/csv_format.h"

namespace sigmafem {

std::vector<std::string> observation_columns(int point_count, bool frame_time) {
  std::vector<std::string> columns = {"step", "time", "so_x", "so_y", "so_z"};
  if (frame_time) columns.insert(columns.begin() + 2, "frame_time");
  for (int p = 0; p < point_count; ++p)
    for (const char* axis : {"_x", "_y", "_z"}) columns.push_back("p" + std::to_string(p) + axis);
  return columns;
}

ObservationTable read_observations_csv(const std::string& path, int point_count, double dt) {
  std::vector<std::string> columns = observation_columns(point_count);
  ObservationTable table;
  bool timed = false;   // the header has frame_time
  std::size_t so_column = 2;
  std::vector<std::vector<double>> point_rows;
  std::vector<Eigen::Vector3d> so_rows;
  auto on_line = [&](const std::vector<std::string>& fields, const std::string& at, bool is_header) {
    if (is_header) {
      if (fields == columns) return;
      if (fields == observation_columns(point_count, true)) {
        timed = true;
        so_column = 3;
        columns = observation_columns(point_count, true);
        return;
      }
      // Name the first column that differs, so a user sees which one to fix.
      std::size_t k = 0;
      while (k < fields.size() && k < columns.size() && fields[k] == columns[k]) ++k;
      const std::string wrong =
          k < fields.size() && k < columns.size()
              ? "column " + std::to_string(k + 1) + " is \"" + fields[k] + "\", expected \"" + columns[k] + "\""
              : "found " + std::to_string(fields.size()) + " columns, expected " + std::to_string(columns.size());
      throw InputError(at + "the header does not match the scenario's " + std::to_string(point_count) +
                       " observed points (step,time,so_x,so_y,so_z,p0_x,...,p" +
                       std::to_string(point_count - 1) + "_z, with frame_time after time for frames at their own "
                       "times): " + wrong);
    }
    if (fields.size() != columns.size())
      throw InputError(at + "expected " + std::to_string(columns.size()) + " fields, found " +
                       std::to_string(fields.size()));
    std::vector<double> values(columns.size(), std::numeric_limits<double>::quiet_NaN());
    for (std::size_t k = 0; k < fields.size(); ++k) {
      const bool may_be_empty = k >= so_column + 3 || (timed && k == 2);   // a point, or no frame
      if (fields[k].empty() && may_be_empty) continue;   // not observed at this step
      if (!parse_double(fields[k], values[k])) {
        const std::string problem =
            fields[k].empty() ? "is empty (only observed points and frame_time may be missing)"
                              : "is not a finite number: \"" + fields[k] + "\"";
        throw InputError(at + "column " + columns[k] + " " + problem);
      }
      // Positions are in metres: far beyond any organ is a unit slip or a corrupt value,
      // and squared in the filter it would overflow.
      if (k >= so_column && std::fabs(values[k]) > kMaxPositionMagnitude)
        throw InputError(at + "column " + columns[k] + " is " + fields[k] +
                         " m, farther than " + format_number(kMaxPositionMagnitude) +
                         " m from the origin; positions are in metres");
    }
    const int expected_step = static_cast<int>(table.steps.size());
    if (values[0] != static_cast<double>(expected_step))
      throw InputError(at + "step " + format_number(values[0]) + " is out of order: expected " +
                       std::to_string(expected_step) + " (rows are consecutive steps from 0)");
    const double expected_time = expected_step * dt;
    if (std::fabs(values[1] - expected_time) > 1e-6 * dt + 1e-9)
      throw InputError(at + "time " + format_number(values[1]) + " is not step * dt = " +
                       format_number(expected_time) + " (the scenario's dt is " +
                       format_number(dt) + " s)");
    if (timed) {
      // A frame belongs to the step whose interval (t - dt, t] holds it; row 0 is the rest
      // state, taken at 0.
      const double frame = values[2];
      double share = 1.0;
      if (!std::isnan(frame)) {
        const double slack = 1e-6 * dt;
        if (expected_step == 0 ? std::fabs(frame) > slack
                               : !(frame > expected_time - dt + slack && frame <= expected_time + slack))
          throw InputError(at + "frame_time " + fields[2] + " lies outside the row's step " +
                           (expected_step == 0 ? std::string("(row 0 is the rest state, at time 0)")
                                               : "(" + format_number(expected_time - dt) + ", " +
                                                     format_number(expected_time) + "] s") +
                           ": give each frame to the step it was taken in");
        if (expected_step > 0) share = std::min(1.0, (frame - (expected_time - dt)) / dt);
      }
      table.frame_times.push_back(frame);
      table.frame_shares.push_back(share);
    }
    table.steps.push_back(expected_step);
    table.times.push_back(values[1]);
    so_rows.emplace_back(values[so_column], values[so_column + 1], values[so_column + 2]);
    point_rows.emplace_back(values.begin() + static_cast<std::ptrdiff_t>(so_column + 3), values.end());
  };
  table.comments = read_csv_file(path, "observations " + path, on_line);
  const bool any_point = std::any_of(point_rows.begin(), point_rows.end(), [](const std::vector<double>& row) {
    return std::any_of(row.begin(), row.end(), [](double v) { return !std::isnan(v); });
  });
  if (point_count > 0 && !any_point)
    throw InputError("observations " + path + ": no observed point has a value in any row; nothing to compare the model with");
  const Eigen::Index rows = static_cast<Eigen::Index>(table.steps.size());
  table.so.resize(rows, 3);
  table.points.resize(rows, 3 * point_count);
  for (Eigen::Index k = 0; k < rows; ++k) {
    table.so.row(k) = so_rows[k].transpose();
    for (Eigen::Index c = 0; c < 3 * point_count; ++c) table.points(k, c) = point_rows[k][c];
  }
  return table;
}

std::string format_observations_csv(const ObservationTable& table) {
  std::ostringstream out;
  for (const std::string& comment : table.comments) out << "# " << comment << '\n';
  const bool timed = !table.frame_times.empty();
  const std::vector<std::string> columns = observation_columns(table.point_count(), timed);
  for (std::size_t k = 0; k < columns.size(); ++k) out << (k ? "," : "") << columns[k];
  out << '\n';
  for (int k = 0; k < table.row_count(); ++k) {
    out << table.steps[k] << ',' << format_number(table.times[k]);
    if (timed) {
      out << ',';
      const double frame = table.frame_times[static_cast<std::size_t>(k)];
      if (!std::isnan(frame)) out << format_number(frame);
    }
    for (int a = 0; a < 3; ++a) out << ',' << format_number(table.so(k, a));
    for (Eigen::Index c = 0; c < table.points.cols(); ++c) {
      out << ',';
      if (!std::isnan(table.points(k, c))) out << format_number(table.points(k, c));
    }
    out << '\n';
  }
  return out.str();
}

}  // namespace sigmafem
