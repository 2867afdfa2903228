#include "host/data/point_cloud_table.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "host/common/input_error.h"
#include "host/common/physical_limits.h"
#include "host/data/csv_fields.h"
#include "host/data/csv_format.h"

namespace sigmafem {

int PointCloudTable::point_count() const {
  int n = 0;
  for (const PointCloudFrame& frame : frames) n += static_cast<int>(frame.points.cols());
  return n;
}

int PointCloudTable::max_frame_points() const {
  int n = 0;
  for (const PointCloudFrame& frame : frames) n = std::max(n, static_cast<int>(frame.points.cols()));
  return n;
}

PointCloudTable read_point_cloud_csv(const std::string& path) {
  static const std::vector<std::string> columns = {"time", "x", "y", "z"};
  PointCloudTable table;
  std::vector<double> time_of_rows;
  std::vector<std::vector<Eigen::Vector3d>> points;   // per frame
  auto on_line = [&](const std::vector<std::string>& fields, const std::string& at, bool is_header) {
    if (is_header) {
      if (fields == columns) return;
      std::string found;
      for (std::size_t k = 0; k < fields.size(); ++k) found += (k ? "," : "") + fields[k];
      throw InputError(at + "the header must be time,x,y,z (one row per measured point), found \"" + found + "\"");
    }
    if (fields.size() != columns.size())
      throw InputError(at + "expected 4 fields (time,x,y,z), found " + std::to_string(fields.size()));
    double values[4];
    for (std::size_t k = 0; k < 4; ++k) {
      if (!parse_double(fields[k], values[k]))
        throw InputError(at + "column " + columns[k] + " " +
                         (fields[k].empty() ? std::string("is empty") : "is not a finite number: \"" + fields[k] + "\""));
      if (k > 0 && std::fabs(values[k]) > kMaxPositionMagnitude)
        throw InputError(at + "column " + columns[k] + " is " + fields[k] + " m, farther than " +
                         format_number(kMaxPositionMagnitude) + " m from the origin; positions are in metres");
    }
    const double t = values[0];
    if (t < 0.0) throw InputError(at + "time " + fields[0] + " is negative");
    if (table.frames.empty() || t != table.frames.back().time) {
      if (!table.frames.empty() && t < table.frames.back().time)
        throw InputError(at + "time " + fields[0] + " comes before the previous frame's " +
                         format_number(table.frames.back().time) +
                         " s: the rows of a frame must be together and the frames in time order");
      table.frames.push_back({t, {}});
      points.emplace_back();
    }
    if (points.back().size() >= static_cast<std::size_t>(kMaxCloudPoints))
      throw InputError(at + "the frame at " + fields[0] + " s has more than " + std::to_string(kMaxCloudPoints) +
                       " points; sample the camera's frame down to a few thousand");
    points.back().emplace_back(values[1], values[2], values[3]);
  };
  table.comments = read_csv_file(path, "point cloud " + path, on_line);
  for (std::size_t f = 0; f < table.frames.size(); ++f) {
    Eigen::Matrix3Xd& m = table.frames[f].points;
    m.resize(3, static_cast<Eigen::Index>(points[f].size()));
    for (std::size_t i = 0; i < points[f].size(); ++i) m.col(static_cast<Eigen::Index>(i)) = points[f][i];
  }
  return table;
}

std::vector<StepFrames> frames_by_step(const PointCloudTable& table, double dt, int rows, const std::string& path) {
  std::vector<StepFrames> by_step(static_cast<std::size_t>(rows));
  for (const PointCloudFrame& frame : table.frames) {
    // The step whose interval ((k-1) dt, k dt] holds the frame; a time on the grid, up to
    // rounding, belongs to the step it ends.
    const double step = std::ceil(frame.time / dt - 1e-9);
    if (step >= rows)
      throw InputError("point cloud " + path + ": the frame at " + format_number(frame.time) +
                       " s lies after the last row of observations.csv (step " + std::to_string(rows - 1) + ", " +
                       format_number((rows - 1) * dt) + " s): the SO's positions must cover every frame");
    if (step < 1.0) continue;
    double share = (frame.time - (step - 1.0) * dt) / dt;
    share = std::abs(share - 1.0) < 1e-9 ? 1.0 : std::clamp(share, 1e-9, 1.0);
    StepFrames& slot = by_step[static_cast<std::size_t>(step)];
    const Eigen::Index before = slot.points.cols(), added = frame.points.cols();
    slot.points.conservativeResize(3, before + added);
    slot.points.rightCols(added) = frame.points;
    slot.share.conservativeResize(before + added);
    slot.share.tail(added).setConstant(share);
  }
  return by_step;
}

std::string format_point_cloud_csv(const PointCloudTable& table) {
  std::ostringstream out;
  for (const std::string& comment : table.comments) out << "# " << comment << '\n';
  out << "time,x,y,z\n";
  for (const PointCloudFrame& frame : table.frames)
    for (Eigen::Index i = 0; i < frame.points.cols(); ++i)
      out << format_number(frame.time) << ',' << format_number(frame.points(0, i)) << ','
          << format_number(frame.points(1, i)) << ',' << format_number(frame.points(2, i)) << '\n';
  return out.str();
}

}  // namespace sigmafem
