// SpringCorrection: a factor shared by the sigma points made exact for each one's own spring
// stiffnesses, by the Woodbury identity (issue 18).
// The sigma points of a ligament estimation differ from the representative whose factor they
// share (FactorisedPreconditioner, A = P^T L L^T P) mostly by the stiffness of the estimated
// ligaments: a few nodes' springs, on the diagonal of A. With E the unit columns of those m
// rows and Delta the sigma point's diagonal difference there, V = L^-1 P E and G = V^T V
// (= E^T A^-1 E),
//   (A + E Delta E^T)^-1 = P^T L^-T (I - V H V^T) L^-1 P,   H = (I + Delta G)^-1 Delta,
// so between the two substitutions of a solve with the shared factor, y -= V H (V^T y) makes
// it a solve with the sigma point's own springs. V's columns are zero outside the rows the
// spring rows reach in L (their ancestors in the elimination tree: the separators above them
// under nested dissection), so the correction touches those rows only: 3987 of the 38k
// liver's 22527 (27 spring rows). V costs m forward substitutions at each factorisation. What the
// sigma points still differ by, the elements' rotations and any region modulus, CG mends as
// before. Measured (bench/RESULTS.md, stop 51): the 38k liver's filter step 5.6 -> 1.8 CG
// iterations.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "host/model/estimated_parameters.h"
#include "host/model/model.h"
#include "host/reference/factorised_preconditioner.h"

namespace sigmafem {

// The rows whose springs the sigma points set themselves: the three of each node of an
// estimated ligament, in increasing order.
std::vector<int> estimated_spring_rows(const Model& model, const EstimatedParameters& estimated);

class SpringCorrection {
 public:
  // At the m rows `rows` of A (none: no correction).
  explicit SpringCorrection(std::vector<int> rows = {}) : rows_(std::move(rows)) {}
  // V = L^-1 P E and G = V^T V for the factor (ready).
  void prepare(const FactorisedPreconditioner& factor);
  bool prepared() const { return prepared_; }
  const std::vector<int>& rows() const { return rows_; }
  int size() const { return static_cast<int>(rows_.size()); }
  // The rows of L (in L's order, increasing) where some column of V is not zero, and V there:
  // reached()[u]'s row of V is reached_values().row(u) (reached rows x m).
  const std::vector<int>& reached() const { return reached_; }
  const Eigen::MatrixXd& reached_values() const { return values_; }
  // H = (I + Delta G)^-1 Delta for the diagonal difference `delta` (m) at the rows.
  Eigen::MatrixXd coupling(const Eigen::VectorXd& delta) const;
  // z = A^-1 r (the factor's solve) made (A + E Delta E^T)^-1 r for `coupling` = H:
  // z -= A^-1 E H E^T z, with one more solve (on the host; the kernels correct between the
  // substitutions instead).
  void apply(const FactorisedPreconditioner& factor, const Eigen::MatrixXd& coupling,
             Eigen::VectorXd& z) const;

 private:
  std::vector<int> rows_;
  std::vector<int> reached_;
  Eigen::MatrixXd values_;    // V at the reached rows
  Eigen::MatrixXd gathered_;  // G = V^T V, m x m
  bool prepared_ = false;
};

}  // namespace sigmafem
