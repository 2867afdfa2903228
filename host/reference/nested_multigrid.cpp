#include "host/reference/nested_multigrid.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

#include "host/common/device_error.h"

namespace sigmafem {
namespace {

// The interpolation to a mesh of `nodes` from the one its elements' parents (8 children each)
// form, or an empty matrix where the elements are not such children. `coarse_elements` gets
// the parents' corners.
RowMajorMatrix prolongation_of(const std::vector<Eigen::Vector3d>& nodes,
                               const std::vector<std::array<int, 4>>& elements,
                               std::vector<std::array<int, 4>>& coarse_elements) {
  const std::size_t n = nodes.size();
  if (elements.empty() || elements.size() % 8 != 0) return RowMajorMatrix();
  coarse_elements.clear();
  // Corner child k of a parent (a, b, c, d) holds corner k at place k and, at its others, the
  // midpoints of the edges from it (refine_uniform's kCornerChildren).
  constexpr int kMidpoint[4][4] = {{-1, 0, 1, 2}, {0, -1, 3, 4}, {1, 3, -1, 5}, {2, 4, 5, -1}};
  constexpr int kEdgeEnds[6][2] = {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 3}, {2, 3}};
  std::vector<std::array<int, 2>> parents(n, {-1, -1});
  int coarse_nodes = 0;
  for (std::size_t e = 0; e < elements.size(); e += 8) {
    std::array<int, 4> corner{};
    for (int k = 0; k < 4; ++k) corner[k] = elements[e + k][k];
    std::array<int, 6> midpoint{};
    midpoint.fill(-1);
    for (int k = 0; k < 4; ++k)
      for (int j = 0; j < 4; ++j) {
        if (j == k) continue;
        const int node = elements[e + k][j];
        int& at = midpoint[kMidpoint[k][j]];
        if (at >= 0 && at != node) return RowMajorMatrix();   // two children disagree
        at = node;
      }
    for (int i = 0; i < 6; ++i) {
      std::array<int, 2> ends = {corner[kEdgeEnds[i][0]], corner[kEdgeEnds[i][1]]};
      if (ends[0] > ends[1]) std::swap(ends[0], ends[1]);
      std::array<int, 2>& known = parents[static_cast<std::size_t>(midpoint[i])];
      if (known[0] >= 0 && known != ends) return RowMajorMatrix();
      known = ends;
    }
    for (int c : corner) coarse_nodes = std::max(coarse_nodes, c + 1);
    coarse_elements.push_back(corner);
  }
  // The coarse nodes come first, every one a corner, every later node a midpoint there.
  std::vector<bool> corner_seen(static_cast<std::size_t>(coarse_nodes), false);
  for (const auto& t : coarse_elements)
    for (int c : t) corner_seen[static_cast<std::size_t>(c)] = true;
  if (std::find(corner_seen.begin(), corner_seen.end(), false) != corner_seen.end()) return RowMajorMatrix();
  double size = 0.0;
  for (const Eigen::Vector3d& x : nodes) size = std::max(size, x.cwiseAbs().maxCoeff());
  std::vector<Eigen::Triplet<double>> entries;
  for (std::size_t i = 0; i < n; ++i) {
    const int row = 3 * static_cast<int>(i);
    if (i < static_cast<std::size_t>(coarse_nodes)) {
      if (parents[i][0] >= 0) return RowMajorMatrix();   // a corner cannot be a midpoint too
      for (int k = 0; k < 3; ++k) entries.emplace_back(row + k, row + k, 1.0);
      continue;
    }
    const auto [a, b] = parents[i];
    if (a < 0 || b >= coarse_nodes) return RowMajorMatrix();
    const Eigen::Vector3d middle = 0.5 * (nodes[static_cast<std::size_t>(a)] + nodes[static_cast<std::size_t>(b)]);
    if ((nodes[i] - middle).norm() > 1e-9 * std::max(size, 1.0)) return RowMajorMatrix();
    for (int k = 0; k < 3; ++k) {
      entries.emplace_back(row + k, 3 * a + k, 0.5);
      entries.emplace_back(row + k, 3 * b + k, 0.5);
    }
  }
  RowMajorMatrix P(3 * static_cast<Eigen::Index>(n), 3 * static_cast<Eigen::Index>(coarse_nodes));
  P.setFromTriplets(entries.begin(), entries.end());
  P.makeCompressed();
  return P;
}

// The largest eigenvalue of D^-1 A (that of the symmetric D^-1/2 A D^-1/2), by power
// iteration from a fixed start, so that every run gets the same bits.
double largest_eigenvalue(const RowMajorMatrix& A, const Eigen::VectorXd& diagonal) {
  const Eigen::VectorXd scale = diagonal.cwiseSqrt().cwiseInverse();
  Eigen::VectorXd v(A.rows());
  for (Eigen::Index i = 0; i < v.size(); ++i) v[i] = 1.0 + static_cast<double>(i % 7) / 7.0;
  v.normalize();
  double lambda = 0.0;
  for (int k = 0; k < 40; ++k) {
    const Eigen::VectorXd w = scale.cwiseProduct(A * scale.cwiseProduct(v));
    lambda = v.dot(w);
    v = w.normalized();
  }
  return lambda;
}

// Chebyshev's recurrence on [lambda_max 1.1 / range, lambda_max 1.1] (Saad, "Iterative
// methods for sparse linear systems", algorithm 12.1, with D^-1 as the preconditioner).
std::vector<NestedMultigrid::ChebyshevStep> chebyshev_steps(double lambda_max, int degree) {
  const double high = 1.1 * lambda_max, low = high / NestedMultigrid::kSmoothingRange;
  const double theta = 0.5 * (high + low), delta = 0.5 * (high - low), sigma = theta / delta;
  std::vector<NestedMultigrid::ChebyshevStep> steps(static_cast<std::size_t>(degree));
  double rho = 1.0 / sigma;
  steps[0] = {0.0, 1.0 / theta};
  for (std::size_t k = 1; k < steps.size(); ++k) {
    const double next = 1.0 / (2.0 * sigma - rho);
    steps[k] = {next * rho, 2.0 * next / delta};
    rho = next;
  }
  return steps;
}

}  // namespace

void check_level_size(const RowMajorMatrix& M, std::size_t rows, std::size_t nonzeros) {
  if (static_cast<std::size_t>(M.rows()) != rows || static_cast<std::size_t>(M.nonZeros()) != nonzeros)
    throw DeviceError("a multigrid level of " + std::to_string(M.rows()) + " rows and " +
                      std::to_string(M.nonZeros()) + " entries where the first had " + std::to_string(rows) +
                      " and " + std::to_string(nonzeros));
}

std::vector<RowMajorMatrix> nested_prolongations(const Model& model) {
  std::vector<RowMajorMatrix> prolongations;
  std::vector<Eigen::Vector3d> nodes = model.rest_positions;
  std::vector<std::array<int, 4>> elements;
  for (const ElementRest& e : model.elements) elements.push_back(e.nodes);
  for (;;) {
    std::vector<std::array<int, 4>> coarse;
    RowMajorMatrix P = prolongation_of(nodes, elements, coarse);
    if (P.size() == 0) break;
    nodes.resize(static_cast<std::size_t>(P.cols() / 3));
    elements = std::move(coarse);
    prolongations.push_back(std::move(P));
  }
  return prolongations;
}

NestedMultigrid::NestedMultigrid(std::vector<RowMajorMatrix> prolongations, int dense_coarsest_rows)
    : prolongations_(std::move(prolongations)), dense_coarsest_rows_(dense_coarsest_rows) {
  if (prolongations_.empty()) throw std::invalid_argument("NestedMultigrid: a mesh that was not refined");
}

bool NestedMultigrid::set_matrix(const Eigen::SparseMatrix<double>& A) {
  ready_ = false;
  levels_.assign(prolongations_.size() + 1, Level());
  levels_[0].matrix = A;
  double setup = 0.0, cycle = 0.0;
  for (std::size_t l = 0; l < levels_.size(); ++l) {
    Level& level = levels_[l];
    if (l > 0) {
      const Level& finer = levels_[l - 1];
      level.matrix = RowMajorMatrix(finer.restriction * finer.matrix * finer.prolongation);
    }
    level.matrix.makeCompressed();
    level.diagonal = level.matrix.diagonal();
    if (!(level.diagonal.array() > 0.0).all() || !level.diagonal.allFinite()) return false;
    const double nonzeros = static_cast<double>(level.matrix.nonZeros());
    const bool coarsest = l + 1 == levels_.size();
    if (!coarsest) {
      level.prolongation = prolongations_[l];
      level.restriction = RowMajorMatrix(prolongations_[l].transpose());
      level.restriction.makeCompressed();
    }
    if (coarsest && level.matrix.rows() <= dense_coarsest_rows_) {
      const Eigen::LLT<Eigen::MatrixXd> llt{Eigen::MatrixXd(level.matrix)};
      if (llt.info() != Eigen::Success) return false;
      coarsest_inverse_ =
          Eigen::MatrixXd(llt.solve(Eigen::MatrixXd::Identity(level.matrix.rows(), level.matrix.rows())))
              .sparseView(0.0, 0.0);
      coarsest_inverse_.makeCompressed();
      const double n = static_cast<double>(level.matrix.rows());
      setup += n * n * n;   // the factorisation and the n solves
      cycle += n * n;
      continue;
    }
    level.lambda_max = largest_eigenvalue(level.matrix, level.diagonal);
    if (!std::isfinite(level.lambda_max) || level.lambda_max <= 0.0) return false;
    level.smoothing = chebyshev_steps(level.lambda_max, coarsest ? kCoarsestDegree : kSmoothingDegree);
    if (coarsest) coarsest_inverse_ = RowMajorMatrix();
    setup += (4.0 + 40.0) * nonzeros;   // the Galerkin product, roughly, and the power iteration
    cycle += coarsest ? kCoarsestDegree * nonzeros
                      : (2.0 * kSmoothingDegree + 1.0) * nonzeros + 2.0 * static_cast<double>(level.prolongation.nonZeros());
  }
  setup_in_cycles_ = setup / cycle;
  ready_ = true;
  return true;
}

void NestedMultigrid::smooth(int l, const Eigen::VectorXd& b, Eigen::VectorXd& x, bool from_zero,
                             const Eigen::VectorXd& shift) const {
  const Level& level = levels_[static_cast<std::size_t>(l)];
  const bool shifted = l == 0 && shift.size() > 0;
  const Eigen::VectorXd diagonal = shifted ? Eigen::VectorXd(level.diagonal + shift) : level.diagonal;
  Eigen::VectorXd p = Eigen::VectorXd::Zero(b.size());
  for (std::size_t k = 0; k < level.smoothing.size(); ++k) {
    Eigen::VectorXd r = b;
    if (k > 0 || !from_zero) {
      r -= level.matrix * x;
      if (shifted) r -= shift.cwiseProduct(x);
    }
    p = level.smoothing[k].previous * p + level.smoothing[k].residual * r.cwiseQuotient(diagonal);
    x += p;
  }
}

Eigen::VectorXd NestedMultigrid::cycle(int l, const Eigen::VectorXd& b, const Eigen::VectorXd& shift) const {
  const Level& level = levels_[static_cast<std::size_t>(l)];
  Eigen::VectorXd x = Eigen::VectorXd::Zero(b.size());
  if (l + 1 == level_count()) {
    if (coarsest_inverted()) return coarsest_inverse_ * b;
    smooth(l, b, x, true, shift);
    return x;
  }
  smooth(l, b, x, true, shift);
  Eigen::VectorXd r = b - level.matrix * x;
  if (l == 0 && shift.size() > 0) r -= shift.cwiseProduct(x);
  x += level.prolongation * cycle(l + 1, level.restriction * r, shift);
  smooth(l, b, x, false, shift);
  return x;
}

std::vector<double> NestedMultigrid::smoothing_coefficients(int l) const {
  std::vector<double> coefficients;
  for (const ChebyshevStep& step : level(l).smoothing) coefficients.insert(coefficients.end(), {step.previous, step.residual});
  return coefficients;
}

std::vector<MultigridLaunch> NestedMultigrid::launches() const {
  if (!ready_) throw std::logic_error("NestedMultigrid: launches before a successful set_matrix");
  std::vector<MultigridLaunch> launches;
  plan(0, launches);
  return launches;
}

void NestedMultigrid::plan_smoothing(int l, int& current, bool from_zero, bool to_result,
                                     std::vector<MultigridLaunch>& launches) const {
  using Role = MultigridVector::Role;
  const int degree = static_cast<int>(levels_[static_cast<std::size_t>(l)].smoothing.size());
  for (int k = 0; k < degree; ++k) {
    const int next = 1 - current;
    MultigridLaunch launch;
    launch.kind = MultigridLaunch::Kind::smooth;
    launch.level = l;
    launch.step = k;
    launch.from_zero = from_zero && k == 0;
    launch.shifted = l == 0;
    launch.in = {l, Role::rhs};
    launch.x = {l, current == 0 ? Role::x0 : Role::x1};
    launch.p = {l, k % 2 == 0 ? Role::p0 : Role::p1};
    launch.out = {l, to_result && k + 1 == degree ? Role::result : (next == 0 ? Role::x0 : Role::x1)};
    launch.p_out = {l, k % 2 == 0 ? Role::p1 : Role::p0};
    launches.push_back(launch);
    current = next;
  }
}

void NestedMultigrid::plan(int l, std::vector<MultigridLaunch>& launches) const {
  using Role = MultigridVector::Role;
  using Kind = MultigridLaunch::Kind;
  const auto launch = [&](Kind kind, MultigridVector in, MultigridVector out) {
    MultigridLaunch one;
    one.kind = kind;
    one.level = l;
    one.in = in;
    one.out = out;
    return one;
  };
  int current = 0;
  if (l + 1 == level_count()) {   // the same as cycle()'s coarsest
    if (coarsest_inverted())
      launches.push_back(launch(Kind::inverse, {l, Role::rhs}, {l, Role::result}));
    else
      plan_smoothing(l, current, true, true, launches);
    return;
  }
  plan_smoothing(l, current, true, false, launches);
  const MultigridVector x = {l, current == 0 ? Role::x0 : Role::x1};
  MultigridLaunch residual = launch(Kind::residual, {l, Role::rhs}, {l, Role::residual});
  residual.x = x;
  residual.shifted = l == 0;
  launches.push_back(residual);
  launches.push_back(launch(Kind::restriction, {l, Role::residual}, {l + 1, Role::rhs}));
  plan(l + 1, launches);
  launches.push_back(launch(Kind::prolongation, {l + 1, Role::result}, x));
  plan_smoothing(l, current, false, true, launches);
}

void NestedMultigrid::operator()(const Eigen::VectorXd& r, Eigen::VectorXd& z, const Eigen::VectorXd& shift) const {
  if (!ready_) throw std::logic_error("NestedMultigrid: applied before a successful set_matrix");
  z = cycle(0, r, shift);
}

}  // namespace sigmafem
