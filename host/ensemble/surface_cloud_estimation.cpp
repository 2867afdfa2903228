#include "host/ensemble/surface_cloud_estimation.h"

#include <algorithm>
#include <cmath>

#include "host/common/input_error.h"
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
