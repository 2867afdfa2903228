#include "host/engine/surface_cloud_estimation.h"

#include <algorithm>
#include <cmath>

#include "host/common/input_error.h"
#include "host/common/machine_memory.h"
#include "host/data/csv_format.h"
#include "host/engine/make_ensemble.h"
#include "host/ensemble/effect_ensemble.h"

namespace sigmafem {

PointCloudOptions take_outlier_gate(RoukfOptions& roukf) {
  PointCloudOptions options;
  options.observation_std = roukf.observation_std;
  options.outlier_gate = roukf.outlier_gate;
  roukf.outlier_gate.enabled = false;
  return options;
}

SurfaceCloudEstimation make_surface_cloud_estimation(const std::string& backend, const Model& model,
                                                     const Mesh& mesh, const EstimatedParameters& estimated,
                                                     int sigma_count, const DeviceOptions& device,
                                                     const PointCloudTable& cloud, double dt, int rows,
                                                     const std::string& path, RoukfOptions& roukf,
                                                     const std::vector<std::string>& effects) {
  SurfaceCloudEstimation estimation;
  estimation.frames = frames_by_step(cloud, dt, rows, path);
  const bool any_frame = std::any_of(estimation.frames.begin(), estimation.frames.end(),
                                     [](const StepFrames& step) { return step.points.cols() > 0; });
  if (!any_frame)
    throw InputError("point cloud " + path + ": no frame after the rest state (t > 0); nothing to compare the "
                     "model with");
  const BoundarySurface surface = boundary_surface(mesh);
  const auto triangles = static_cast<Eigen::Index>(surface.triangles.size());
  estimation.surface_triangles = static_cast<int>(triangles);
  // The data matrix and the run's innovations and their stds are rows x triangles each:
  // refuse what would not fit in half the memory before allocating it.
  const double needed = 3.0 * 8.0 * static_cast<double>(rows) * static_cast<double>(triangles);
  const double available = physical_memory_bytes();
  if (available > 0.0 && needed > 0.5 * available)
    throw InputError("point cloud " + path + ": " + std::to_string(rows) + " steps of a surface of " +
                     std::to_string(triangles) + " triangles need about " + format_number(std::ceil(needed / 1e9)) +
                     " GB, more than half of this machine's memory; estimate fewer steps per run");
  estimation.measured = Eigen::MatrixXd::Constant(rows, triangles, std::nan(""));
  for (std::size_t k = 0; k < estimation.frames.size(); ++k)
    if (estimation.frames[k].points.cols() > 0) estimation.measured.row(static_cast<Eigen::Index>(k)).setZero();
  const PointCloudOptions options = take_outlier_gate(roukf);
  const ObservedPoints observed(surface.nodes);
  std::unique_ptr<Ensemble> organ;
  if (effects.empty())
    organ = make_ensemble(backend, model, estimated, observed, sigma_count, device);
  else
    organ = make_effect_ensemble(backend, model, estimated, observed, sigma_count, device, effects);
  estimation.ensemble = std::make_unique<PointCloudObservation>(std::move(organ), surface.triangles, options);
  return estimation;
}

}  // namespace sigmafem
