#include "host/reference/spring_correction.h"

#include <Eigen/LU>
#include <algorithm>

namespace sigmafem {

std::vector<int> estimated_spring_rows(const Model& model, const EstimatedParameters& estimated) {
  std::vector<int> nodes;
  for (int l : estimated.ligaments)
    for (int node : model.ligaments[static_cast<std::size_t>(l)].nodes) nodes.push_back(node);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  std::vector<int> rows;
  for (int node : nodes)
    for (int k = 0; k < 3; ++k) rows.push_back(3 * node + k);
  return rows;
}

void SpringCorrection::prepare(const FactorisedPreconditioner& factor) {
  const Eigen::SparseMatrix<double>& L = factor.lower();
  const Eigen::Index n = L.rows();
  const Eigen::Index m = static_cast<Eigen::Index>(rows_.size());
  // V's columns by forward substitution in double: entries the column's row does not reach
  // stay exactly zero.
  Eigen::MatrixXd V(n, m);
  Eigen::VectorXd column(n);
  for (Eigen::Index j = 0; j < m; ++j) {
    column.setZero();
    column[factor.order()[rows_[static_cast<std::size_t>(j)]]] = 1.0;
    L.triangularView<Eigen::Lower>().solveInPlace(column);
    V.col(j) = column;
  }
  reached_.clear();
  for (Eigen::Index i = 0; i < n; ++i)
    if ((V.row(i).array() != 0.0).any()) reached_.push_back(static_cast<int>(i));
  values_.resize(static_cast<Eigen::Index>(reached_.size()), m);
  for (std::size_t u = 0; u < reached_.size(); ++u) values_.row(static_cast<Eigen::Index>(u)) = V.row(reached_[u]);
  gathered_ = values_.transpose() * values_;
  prepared_ = true;
}

Eigen::MatrixXd SpringCorrection::coupling(const Eigen::VectorXd& delta) const {
  const Eigen::Index m = static_cast<Eigen::Index>(rows_.size());
  if (m == 0) return Eigen::MatrixXd(0, 0);
  // (I + Delta G) H = Delta. Not symmetric; LU with partial pivoting. I + Delta G is regular
  // while A + E Delta E^T is (det = det(A + E Delta E^T) / det A), which the springs of a
  // sigma point (>= 0) and the mass keep positive definite.
  const Eigen::MatrixXd system = Eigen::MatrixXd::Identity(m, m) + delta.asDiagonal() * gathered_;
  return system.partialPivLu().solve(Eigen::MatrixXd(delta.asDiagonal()));
}

void SpringCorrection::apply(const FactorisedPreconditioner& factor, const Eigen::MatrixXd& coupling,
                             Eigen::VectorXd& z) const {
  const Eigen::Index m = static_cast<Eigen::Index>(rows_.size());
  if (m == 0) return;
  Eigen::VectorXd at_rows(m);
  for (Eigen::Index j = 0; j < m; ++j) at_rows[j] = z[rows_[static_cast<std::size_t>(j)]];
  const Eigen::VectorXd coupled = coupling * at_rows;
  Eigen::VectorXd spread = Eigen::VectorXd::Zero(z.size()), solved;
  for (Eigen::Index j = 0; j < m; ++j) spread[rows_[static_cast<std::size_t>(j)]] = coupled[j];
  factor(spread, solved);
  z -= solved;
}

}  // namespace sigmafem
