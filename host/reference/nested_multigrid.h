// NestedMultigrid: a multigrid V-cycle for the implicit-Euler matrix of a mesh made by uniform
// refinement (a scenario's mesh.refine), CG's preconditioner in OpenCL's GPU form (issue 18).
// There Jacobi took 400 CG iterations a step on the 38k liver, and a GPU cannot run a
// factor's triangular solves, which are sequential; a V-cycle is sparse products only.
//
// Levels: the finest is the matrix A; each coarser one is the Galerkin product P^T A P, P the
// linear interpolation from the mesh the refinement started from (a new node, an edge's
// midpoint, takes the mean of the edge's ends; nested_prolongations). Smoothing: Chebyshev
// polynomials in D^-1 A (D = diag A) of degree kSmoothingDegree on [lambda_max /
// kSmoothingRange, 1.1 lambda_max], lambda_max by power iteration, the same polynomial before
// and after the coarse correction, so the V-cycle is symmetric positive definite, as CG needs.
// The coarsest level: its exact inverse, dense, up to kDenseCoarsestRows rows, else
// kCoarsestDegree Chebyshev steps. Measured on the 38k liver's system at rest (22 527 rows):
// 659 Jacobi iterations to 1e-6 of a random right-hand side, 26 with this V-cycle; the 117k
// box 357 -> 21 (its coarsest, 9 699 rows, smoothed).
//
// The sigma points of an ensemble share one hierarchy, made of the representative's matrix;
// each may add a diagonal of its own at the finest level (its springs against the
// representative's: `shift`), in both the products and D there.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstddef>
#include <vector>

#include "host/model/model.h"

namespace sigmafem {

using RowMajorMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// The interpolations of the uniform refinements that made the model's mesh, finest first:
// P_l takes level l + 1's node values (3 per node) to level l's. Recovered from the
// refinement's numbering (refine_uniform: element e's children are 8e .. 8e + 7, corner child
// k has the parent's corner k at its place k and the edges' midpoints at the others; old
// nodes keep their indices) and checked: every midpoint at its edge's middle, every coarse
// node a corner. Empty for a mesh that was not refined so.
std::vector<RowMajorMatrix> nested_prolongations(const Model& model);

// A vector of a level as the devices hold it, for every sigma point: the level's right-hand
// side and result (the finest level's are CG's r and z), the smoothing's two iterates and two
// steps (a step reads one and writes the other), the residual.
struct MultigridVector {
  enum class Role { rhs, result, x0, x1, p0, p1, residual };
  int level = 0;
  Role role = Role::rhs;
};

// One launch of the V-cycle on a device (OpenClMultigrid, VulkanMultigrid), the same arithmetic
// as NestedMultigrid's operator(): a Chebyshev step of `level`'s smoothing (`step` k, from zero
// or not; in: b, x, p -> out: x, p_out), its residual (in: b, x -> out), the restriction of
// the residual to the next level's right-hand side, the prolongation of that level's result
// added into x (in -> out), or the coarsest level's inverse (in -> out). `shifted`: the finest
// level, where each sigma point adds its shift.
struct MultigridLaunch {
  enum class Kind { smooth, residual, restriction, prolongation, inverse };
  Kind kind = Kind::smooth;
  int level = 0;
  int step = 0;
  bool from_zero = false;
  bool shifted = false;
  MultigridVector in, x, p, out, p_out;
};

// The buffer a device back end holds for `v` (OpenClMultigrid, VulkanMultigrid), from its
// levels (each with b, correction, x[2], p[2], r): the finest level's right-hand side and
// result are CG's r and z.
template <class Buffer, class Level>
const Buffer& multigrid_buffer(const std::vector<Level>& levels, const MultigridVector& v, const Buffer& r,
                               const Buffer& z) {
  const Level& level = levels[static_cast<std::size_t>(v.level)];
  switch (v.role) {
    case MultigridVector::Role::rhs: return v.level == 0 ? r : level.b;
    case MultigridVector::Role::result: return v.level == 0 ? z : level.correction;
    case MultigridVector::Role::x0: return level.x[0];
    case MultigridVector::Role::x1: return level.x[1];
    case MultigridVector::Role::p0: return level.p[0];
    case MultigridVector::Role::p1: return level.p[1];
    case MultigridVector::Role::residual: break;
  }
  return level.r;
}

class NestedMultigrid {
 public:
  static constexpr int kSmoothingDegree = 3;
  static constexpr double kSmoothingRange = 30.0;
  static constexpr int kDenseCoarsestRows = 3000;
  static constexpr int kCoarsestDegree = 16;

  // One step of a Chebyshev smoothing: r = b - A x, p = previous p + residual D^-1 r, x += p.
  struct ChebyshevStep {
    double previous = 0.0;
    double residual = 0.0;
  };
  struct Level {
    RowMajorMatrix matrix;         // A_l
    Eigen::VectorXd diagonal;      // diag A_l
    double lambda_max = 0.0;       // of D^-1 A_l
    std::vector<ChebyshevStep> smoothing;
    RowMajorMatrix prolongation;   // to this level from the next coarser (none on the coarsest)
    RowMajorMatrix restriction;    // its transpose
  };

  // `prolongations`: nested_prolongations() of the model; at least one. The coarsest level is
  // inverted where it has at most `dense_coarsest_rows` rows (tests lower it).
  explicit NestedMultigrid(std::vector<RowMajorMatrix> prolongations,
                           int dense_coarsest_rows = kDenseCoarsestRows);

  // Makes the levels of A (symmetric positive definite, the finest level's matrix). Returns
  // false, leaving the hierarchy unusable, when a level is not positive definite.
  bool set_matrix(const Eigen::SparseMatrix<double>& A);
  bool ready() const { return ready_; }
  int level_count() const { return static_cast<int>(levels_.size()); }
  const Level& level(int l) const { return levels_[static_cast<std::size_t>(l)]; }
  // The coarsest level's inverse (rows x rows, every entry stored) where it is solved exactly;
  // else empty, and the coarsest level's `smoothing` (kCoarsestDegree steps) stands in.
  const RowMajorMatrix& coarsest_inverse() const { return coarsest_inverse_; }
  bool coarsest_inverted() const { return coarsest_inverse_.rows() > 0; }
  // The matrix level l's launches read: A_l, or the coarsest level's inverse where inverted.
  const RowMajorMatrix& launch_matrix(int l) const {
    return l + 1 == level_count() && coarsest_inverted() ? coarsest_inverse_ : level(l).matrix;
  }
  // Level l's smoothing as the devices read it: [2k] previous, [2k + 1] residual of step k.
  std::vector<double> smoothing_coefficients(int l) const;
  // Multiply-adds of set_matrix against one V-cycle's (for a refresh rule, as the factor's).
  double setup_in_cycles() const { return setup_in_cycles_; }
  // The V-cycle as launches, in order (after set_matrix; the same for every matrix of the
  // hierarchy's meshes).
  std::vector<MultigridLaunch> launches() const;

  // z = M^-1 r, one V-cycle from zero; `shift`, empty or one per finest row, added to the
  // finest level's matrix and diagonal.
  void operator()(const Eigen::VectorXd& r, Eigen::VectorXd& z,
                  const Eigen::VectorXd& shift = Eigen::VectorXd()) const;

 private:
  void smooth(int l, const Eigen::VectorXd& b, Eigen::VectorXd& x, bool from_zero,
              const Eigen::VectorXd& shift) const;
  Eigen::VectorXd cycle(int l, const Eigen::VectorXd& b, const Eigen::VectorXd& shift) const;
  void plan(int l, std::vector<MultigridLaunch>& launches) const;
  void plan_smoothing(int l, int& current, bool from_zero, bool to_result, std::vector<MultigridLaunch>& launches) const;
  std::vector<RowMajorMatrix> prolongations_;
  int dense_coarsest_rows_;
  std::vector<Level> levels_;
  RowMajorMatrix coarsest_inverse_;
  double setup_in_cycles_ = 0.0;
  bool ready_ = false;
};

// A device back end's level made for a matrix of `rows` rows and `nonzeros` entries (the first
// hierarchy's) and `M` of a later one: throws DeviceError where they differ.
void check_level_size(const RowMajorMatrix& M, std::size_t rows, std::size_t nonzeros);

// Writes `multigrid`'s values into a device back end's `levels` (OpenClMultigrid,
// VulkanMultigrid), made for the first hierarchy of the same meshes: each level's launch
// matrix, its smoothing's diagonal and steps, its prolongation and restriction, by
// `write_matrix(to, M)` and `write_reals(to, values)`.
template <class Level, class WriteMatrix, class WriteReals>
void write_levels(const NestedMultigrid& multigrid, const std::vector<Level>& levels, WriteMatrix write_matrix,
                  WriteReals write_reals) {
  for (int l = 0; l < multigrid.level_count(); ++l) {
    const NestedMultigrid::Level& from = multigrid.level(l);
    const Level& level = levels[static_cast<std::size_t>(l)];
    write_matrix(level.matrix, multigrid.launch_matrix(l));
    if (!from.smoothing.empty()) {
      write_reals(level.diagonal, std::vector<double>(from.diagonal.data(), from.diagonal.data() + from.diagonal.size()));
      write_reals(level.steps, multigrid.smoothing_coefficients(l));
    }
    if (l + 1 < multigrid.level_count()) {
      write_matrix(level.prolongation, from.prolongation);
      write_matrix(level.restriction, from.restriction);
    }
  }
}

}  // namespace sigmafem
