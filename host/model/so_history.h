// SoHistory: the SO positions of the steps made, so that a simulation can be driven by the SO
// as it was `lag` seconds earlier (the time_lag effect: Model::so_lag plus a per-sigma-point
// lag). Shared by the CPU reference and the device ensembles, so that they lag alike.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace sigmafem {

class SoHistory {
 public:
  // `start`: so(0), where the SO rests before t = 0; `dt`: the step.
  SoHistory(const Eigen::Vector3d& start, double dt);

  // The SO at the end of the next step.
  void push(const Eigen::Vector3d& so_position);

  // The SO `lag` (>= 0) seconds before the end of the last step pushed: linear between the
  // steps' positions, so(0) before t = 0.
  Eigen::Vector3d lagged(double lag) const;

 private:
  std::vector<Eigen::Vector3d> positions_;   // [0]: so(0); [k]: at the end of step k
  double dt_;
};

}  // namespace sigmafem
