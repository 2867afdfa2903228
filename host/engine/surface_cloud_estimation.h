// SurfaceCloudEstimation: what run_estimation needs for point-cloud data (scenario
// observations.surface_cloud, issue 15 item 2), built in one place for `estimate`, the tests
// and the benchmarks: the ensemble of the organ observing its surface nodes, wrapped in the
// point-cloud observation (filter/point_cloud_observation.h), the frames by data row, and the
// data matrix (one row per step, one column per surface triangle: 0 where the step has a frame,
// NaN where it has none; the observation says which triangles its points fell on).
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "filter/point_cloud_observation.h"
#include "filter/roukf.h"
#include "host/model/estimated_parameters.h"
#include "host/common/device_options.h"
#include "host/data/point_cloud_table.h"
#include "host/mesh/mesh.h"
#include "host/model/model.h"

namespace sigmafem {

struct SurfaceCloudEstimation {
  std::unique_ptr<PointCloudObservation> ensemble;
  std::vector<StepFrames> frames;         // by data row (frames_by_step); no point: no frame
  Eigen::MatrixXd measured;               // rows x surface triangles
  int surface_triangles = 0;

  // For run_estimation's before_step: hands row `row`'s frame to the observation.
  void before_step(Eigen::Index row) {
    const StepFrames& step = frames[static_cast<std::size_t>(row)];
    ensemble->set_frame(step.points, step.share);
  }
};

// The point-cloud observation's options from the filter's: the outlier gate moves from the
// filter into the observation, which gates each point before binning it (`roukf`'s gate is
// handed over and turned off there), with the filter's observation std.
PointCloudOptions take_outlier_gate(RoukfOptions& roukf);

// The estimation of `model` (on `mesh`'s boundary surface) from `cloud` over `rows` data rows
// of `dt`, on `backend` (make_ensemble), with the candidate `effects` estimated too
// (EffectEnsemble, for diagnose; its camera offset moves the surface). The outlier gate moves from the filter into the
// observation, which gates each point before binning it: `roukf`'s gate is handed over and
// turned off there. Throws InputError naming `path` when no frame lies after the rest state,
// one lies after the last row, or the run's tables (rows x triangles, three of them) would
// take more than half the machine's memory.
SurfaceCloudEstimation make_surface_cloud_estimation(const std::string& backend, const Model& model,
                                                     const Mesh& mesh, const EstimatedParameters& estimated,
                                                     int sigma_count, const DeviceOptions& device,
                                                     const PointCloudTable& cloud, double dt, int rows,
                                                     const std::string& path, RoukfOptions& roukf,
                                                     const std::vector<std::string>& effects = {});

}  // namespace sigmafem
