// SigmaPoints: the directions V_i and weights of the ROUKF's sigma points (docs/ROUKF.md),
// with the normalisation I_i that the prediction and correction use.
//   simplex: r = p + 1 points, weight alpha = 1/(p+1); sum V_i = 0, alpha sum V_i V_i^T = I_p.
//   star:    r = 2p + 1 points (+-sqrt(p) e_j scaled by sqrt((2p+1)/(2p)), and a zero point),
//            weight 1/(2p+1); the same two identities hold.
// For both sets I = V (alpha V^T V)^-1 restricted to the sigma space: I_i = V_i, since
// alpha V V^T = I_p (the normalisation matrix is the identity); the star set's correction
// uses D_v = alpha^2 I^T I (r x r).
#pragma once

#include <Eigen/Core>
#include <string>

namespace sigmafem {

enum class SigmaPointSet { simplex, star };

// "simplex" or "star"; throws std::invalid_argument otherwise.
SigmaPointSet parse_sigma_point_set(const std::string& name);
const char* to_string(SigmaPointSet set);

struct SigmaPoints {
  SigmaPointSet set = SigmaPointSet::simplex;
  Eigen::MatrixXd directions;   // p x r: column i is V_i (= I_i)
  double alpha = 0.0;           // the weight of every point

  int parameter_count() const { return static_cast<int>(directions.rows()); }
  int count() const { return static_cast<int>(directions.cols()); }
};

SigmaPoints make_sigma_points(SigmaPointSet set, int parameter_count);

// r: p + 1 for the simplex set, 2p + 1 for the star set.
int sigma_point_count(SigmaPointSet set, int parameter_count);

}  // namespace sigmafem
