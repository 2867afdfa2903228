#include "host/ensemble/surface_cloud_estimation.h"

#include <algorithm>
#include <cmath>

#include "host/common/input_error.h"
#include "host/common/machine_memory.h"
#include "host/data/csv_format.h"
#include "host/ensemble/make_ensemble.h"

namespace sigmafem {

SurfaceCloudEstimation make_surface_cloud_estimation(const std::string& backend, const Model& model,
                                                     const Mesh& mesh, const std::vector<int>& estimated,
                                                     int sigma_count, const DeviceOptions& device,
                                                     const PointCloudTable& cloud, double dt, int rows,
                                                     const std::string& path) {
  SurfaceCloudEstimation estimation;
  estimation.frames = frames_by_step(cloud, dt, rows, path);
  Eigen::Index max_points = 0;
  for (const StepFrames& step : estimation.frames) max_points = std::max(max_points, step.points.cols());
  if (max_points == 0)
    throw InputError("point cloud " + path + ": no frame after the rest state (t > 0); nothing to compare the "
                     "model with");
  // The data matrix and the run's innovations and their stds are rows x max_points each:
  // refuse what would not fit in half the memory before allocating it.
  const double needed = 3.0 * 8.0 * static_cast<double>(rows) * static_cast<double>(max_points);
  const double available = physical_memory_bytes();
  if (available > 0.0 && needed > 0.5 * available)
    throw InputError("point cloud " + path + ": " + std::to_string(rows) + " steps of up to " + std::to_string(max_points) +
                     " points need about " + format_number(std::ceil(needed / 1e9)) + " GB, more than half of this "
                     "machine's memory; sample the frames down or estimate fewer steps per run");
  estimation.measured = Eigen::MatrixXd::Constant(rows, max_points, std::nan(""));
  for (std::size_t k = 0; k < estimation.frames.size(); ++k)
    estimation.measured.row(static_cast<Eigen::Index>(k)).head(estimation.frames[k].points.cols()).setZero();
  const BoundarySurface surface = boundary_surface(mesh);
  estimation.surface_triangles = static_cast<int>(surface.triangles.size());
  estimation.ensemble = std::make_unique<PointCloudObservation>(
      make_ensemble(backend, model, estimated, ObservedPoints(surface.nodes), sigma_count, device),
      surface.triangles, static_cast<int>(max_points));
  return estimation;
}

}  // namespace sigmafem
