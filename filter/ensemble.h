// Ensemble: what the filter needs from the simulations, and all it knows of them.
// One object holds the S sigma-point simulations of one organ on one back end (the CPU
// reference, OpenCL, Vulkan); the big per-sigma state (positions, velocities, the state
// block of the ROUKF factor L) stays inside it. Per filter step the filter
//   1. recenter(): re-samples every sigma point's state around the corrected estimate,
//   2. set_parameters(): hands over the S parameter vectors,
//   3. advance(): all S simulations advance one time step with the SO at its measured position,
//   4. predicted_observations(): reads back only the observed positions (3m x S numbers).
// filter/ includes nothing of host/ (no mesh, device or scenario headers); host/ builds on filter/.
#pragma once

#include <Eigen/Core>
#include <stdexcept>
#include <string>
#include <vector>

namespace sigmafem {

// Per-sigma outcome of one advance(): the linear solver's work and status.
struct StepReport {
  std::vector<int> cg_iterations;          // per sigma point
  std::vector<double> relative_residual;   // per sigma point
  std::vector<unsigned> converged;         // per sigma point: 1 converged, 0 hit the cap
  // Factorisations of CG's preconditioner made in this advance (a back end with factors).
  int factorisations = 0;
  int unconverged_count() const {
    int n = 0;
    for (unsigned c : converged) n += c == 0u;
    return n;
  }
};

// The ROUKF's re-sampling of the state (docs/ROUKF.md, steps 1-2), done where the states are.
// With X_i the sigma states left by the last advance():
//   mean = alpha sum_i X_i,  L = alpha sum_i X_i I_i^T        (prediction: mean and factor)
//   X_hat = mean + L correction                                (correction of the last step)
//   L <- L factor                                              (sampling: L C, C C^T = U^-1)
//   X_i = X_hat + L I_i                                        (re-sampled sigma states)
// and the same for the velocities V_i (their own mean, factor and correction): the state of a
// dynamic simulation is both, and a filter that re-sampled positions alone forgot every
// parameter effect carried by momentum (docs/ROUKF.md: on the liver under a declared
// 9.81 m/s^2 a rigid residual bias of 0.052 mm with the true model, 0.011 mm with velocities).
// Before the first advance all sigma states are equal, so L is zero and X_i = X_hat.
struct Recentering {
  double alpha = 0.0;                 // the weight of every sigma point
  Eigen::MatrixXd directions;         // p x S: column i is I_i
  Eigen::VectorXd correction;         // p: the Kalman correction in the factor's coordinates
  Eigen::MatrixXd factor;             // p x p: C
};

// The re-sampled states of `recentering` for the predicted sigma states Y (n x S, one column
// per sigma point), in double precision: what CpuEnsemble::recenter does with its states and
// the distributed ensemble (host/mpi/) with every rank's, so that both give the same bits.
inline Eigen::MatrixXd resampled_states(const Eigen::MatrixXd& Y, const Recentering& r) {
  const Eigen::VectorXd mean = r.alpha * Y.rowwise().sum();
  const Eigen::MatrixXd L = r.alpha * Y * r.directions.transpose();   // n x p
  const Eigen::VectorXd y_hat = mean + L * r.correction;
  return Eigen::MatrixXd(y_hat.replicate(1, Y.cols()) + L * r.factor * r.directions);
}

class Ensemble {
 public:
  virtual ~Ensemble() = default;
  virtual int sigma_count() const = 0;                                  // S
  virtual int parameter_count() const = 0;                              // p
  virtual int observation_count() const = 0;                            // 3m
  // p x S, column s = sigma point s's parameters (log-stiffness of the estimated ligaments).
  virtual void set_parameters(const Eigen::MatrixXd& theta) = 0;
  // One time step for all S with the SO at `so_position` (the SO at the end of the step).
  virtual StepReport advance(const Eigen::Vector3d& so_position) = 0;
  // 3m x S: the observed nodes' positions of every sigma point.
  virtual void predicted_observations(Eigen::MatrixXd& y) const = 0;
  // The consecutive rows of y that belong to one measured point: 3 for a tracked point
  // (x, y, z), 1 for a surface cloud's rows (a triangle's binned distances; filter/
  // point_cloud_observation.h, which gates its points itself).
  // The outlier gate leaves points out, all their rows together.
  virtual int rows_per_point() const { return 3; }
  // Whether the last predicted_observations() predicts data row `row`: a row it does not is
  // left out of that step as a missing datum is (a surface triangle that no point of a cloud's
  // frame fell on, filter/point_cloud_observation.h).
  virtual bool predicts_row(Eigen::Index /*row*/) const { return true; }
  // The measured points the ensemble's own outlier gate left out of the last
  // predicted_observations() (a cloud gates its points before binning them); counted with the
  // filter's own (filter/outlier_gate.h).
  virtual std::vector<int> rejected_points() const { return {}; }
  virtual void recenter(const Recentering& recentering) = 0;
};

// set_parameters' check of theta: p x S for an ensemble of p parameters and S sigma points;
// std::invalid_argument naming `who` otherwise.
inline void check_parameter_matrix(const Eigen::MatrixXd& theta, int p, int S, const std::string& who) {
  if (theta.rows() != p || theta.cols() != S)
    throw std::invalid_argument(who + "::set_parameters: expected a " + std::to_string(p) + " x " +
                                std::to_string(S) + " matrix");
}

}  // namespace sigmafem
