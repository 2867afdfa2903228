// PointCloudTable: surface point clouds, one frame per time stamp (docs/FORMATS.md, "Point
// clouds"): the file pointcloud.csv with columns time,x,y,z, one row per measured point, the
// rows of a frame together (consecutive rows with the same time), frames in time order. A
// frame has any number of points and they carry no identity: point 3 of one frame has
// nothing to do with point 3 of the next. One file rather than a file per frame: it is
// written atomically, streams, and any tool (a depth camera's per-frame PLY files, a
// spreadsheet) produces it with a line of script.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace sigmafem {

struct PointCloudFrame {
  double time = 0.0;         // s
  Eigen::Matrix3Xd points;   // m, one column per point
};

struct PointCloudTable {
  std::vector<std::string> comments;   // written as "# ..." lines before the header
  std::vector<PointCloudFrame> frames; // strictly increasing times
  int point_count() const;             // over all frames
  int max_frame_points() const;        // the most points in one frame
};

// Reads a point-cloud file. Throws InputError naming the file, the line and the column for a
// header other than time,x,y,z, a field that is missing or not a finite number, a position
// farther than kMaxPositionMagnitude from the origin, a negative time, a time that goes back
// (a frame's rows must be together, frames in order), a frame of more than kMaxCloudPoints
// points, or a file with no row.
PointCloudTable read_point_cloud_csv(const std::string& path);

// The points measured during one simulation step, from one frame or several.
struct StepFrames {
  Eigen::Matrix3Xd points = Eigen::Matrix3Xd(3, 0);
  // Per point: when in the step it was taken, in (0, 1]: (t - (k-1) dt) / dt for step k
  // (1: at the step's end, on the grid).
  Eigen::VectorXd share;
};

// The frames by simulation step, for a run of `rows` data rows at steps of `dt`: element k
// holds the frames taken in ((k-1) dt, k dt] (frames of a camera faster than the steps share
// a step: their points are put together), with where in the step each was taken. Row 0 is
// the rest state, where the filter makes no step: a frame at time 0 is left out. Throws
// InputError naming `path` and the frame for one taken after the last row.
std::vector<StepFrames> frames_by_step(const PointCloudTable& table, double dt, int rows, const std::string& path);

// The CSV text of the table.
std::string format_point_cloud_csv(const PointCloudTable& table);

}  // namespace sigmafem
