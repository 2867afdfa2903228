#include "filter/sigma_points.h"

#include <cmath>
#include <stdexcept>

namespace sigmafem {

SigmaPointSet parse_sigma_point_set(const std::string& name) {
  if (name == "simplex") return SigmaPointSet::simplex;
  if (name == "star") return SigmaPointSet::star;
  throw std::invalid_argument("sigma points: expected simplex or star, got '" + name + "'");
}

const char* to_string(SigmaPointSet set) {
  return set == SigmaPointSet::simplex ? "simplex" : "star";
}

SigmaPoints make_sigma_points(SigmaPointSet set, int p) {
  if (p < 1) throw std::invalid_argument("sigma points: need at least one parameter");
  SigmaPoints points;
  points.set = set;
  const double pd = static_cast<double>(p);
  if (set == SigmaPointSet::simplex) {
    // The canonical simplex of Moireau and Chapelle (docs/ROUKF.md), built row by row.
    const int r = p + 1;
    const double beta = pd / (pd + 1.0);
    Eigen::MatrixXd W = Eigen::MatrixXd::Zero(p, r);
    W(0, 0) = -1.0 / std::sqrt(2.0 * beta);
    W(0, 1) = 1.0 / std::sqrt(2.0 * beta);
    for (int i = 1; i < p; ++i) {
      const double id = static_cast<double>(i);
      const double scale = std::sqrt(beta * (id + 1.0) * (id + 2.0));
      for (int j = 0; j <= i; ++j) W(i, j) = 1.0 / scale;
      W(i, i + 1) = -(id + 1.0) / scale;
    }
    points.directions = std::sqrt(pd) * W;
    points.alpha = 1.0 / static_cast<double>(r);
  } else {
    const int r = 2 * p + 1;
    points.directions = Eigen::MatrixXd::Zero(p, r);
    const double scale = std::sqrt(pd) * std::sqrt((2.0 * pd + 1.0) / (2.0 * pd));
    for (int j = 0; j < p; ++j) {
      points.directions(j, 2 * j) = scale;
      points.directions(j, 2 * j + 1) = -scale;
    }
    // the last column is the zero point
    points.alpha = 1.0 / static_cast<double>(r);
  }
  return points;
}

int sigma_point_count(SigmaPointSet set, int parameter_count) {
  return set == SigmaPointSet::simplex ? parameter_count + 1 : 2 * parameter_count + 1;
}

}  // namespace sigmafem
