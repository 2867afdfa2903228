// VtkSeries: a time series of the organ for ParaView: one XML unstructured grid (.vtu) per
// written frame and a .pvd collection that lists them with their times. Each frame holds
// the deformed mesh, the displacement, and integer point fields that mark the ligament
// nodes (ligament index + 1), the observed nodes (observation index + 1) and the control
// nodes (1), so that ParaView's Threshold shows each group; and per tetrahedron its region
// (Model::regions index + 1, 0 outside every region) and its Young's modulus (Pa), so that a
// stiff inclusion shows where it is.
//
// Frames go to `<dir>/vtk/` and finish() writes `<dir>/<name>.pvd`; `dir` is generate's staging
// folder (host/common/output_set.h), so an interrupted run leaves no series behind.
#pragma once

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "host/model/model.h"

namespace sigmafem {

class VtkSeries {
 public:
  VtkSeries(const Model& model, std::vector<int> observed_nodes, std::string directory,
            std::string name);
  // Writes the frame for positions x at time t.
  void write_frame(double t, const Eigen::VectorXd& x);
  // Writes `<dir>/<name>.pvd`.
  void finish();
  int frame_count() const { return static_cast<int>(frames_.size()); }

 private:
  const Model& model_;
  std::vector<int> ligament_mark_, observed_mark_, control_mark_;
  std::vector<int> region_mark_;          // per element
  std::vector<double> young_modulus_;     // per element, Pa
  std::string directory_, name_;
  std::vector<std::pair<double, std::string>> frames_;   // time, file name
};

}  // namespace sigmafem
