// Static equilibria of the reference elasticity (host/model, host/reference/corotational)
// against exact and analytic solutions: the patch test, a bar in uniaxial tension, the
// convergence of a cantilever to Timoshenko beam theory, and a cantilever turned by a large
// rigid rotation, which the co-rotational formulation must solve as the turned small-strain
// problem and plain linear elasticity cannot.
//
// The static solver lives here (the simulation never solves a static problem): assemble the
// tangent with assemble_element_stiffness, keep the free degrees of freedom, and solve with
// Eigen's SimplicialLDLT. Linear elasticity uses the frames of the rest state; the
// co-rotational problem iterates x <- x + K_t(x)^-1 (f_ext + f_int(x)) on the free degrees of
// freedom (a Newton iteration without the rotation's derivative in the tangent, so it
// converges linearly, fast for small strains).
//
// Run time (Release): about 1 s in all, mostly the 80x8x8 cantilever; ASan builds run ~5x slower.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "host/model/model.h"
#include "host/reference/corotational.h"
#include "tests/reference/structured_mesh.h"

namespace sigmafem {
namespace {

// Patch test and uniaxial bar: linear tetrahedra represent linear displacement fields
// exactly, so the only error is the solve's rounding, ~cond(K) eps at worst (measured 5e-16
// and 3e-15 of the field's size).
constexpr double kLinearFieldTolerance = 1e-10;
// The co-rotational iteration stops when the free force residual is this fraction of the
// load. Rounding floors it: each element force is ~E h times positions of ~1 m rounded to
// ~1e-16 m, and their sum over ~1e3 dofs, against a load of 2.5e-4 N, leaves a relative
// residual of ~4e-8 (measured; the iteration reaches it in two steps and stalls there).
// That floor is rounding noise in the stiff modes, which moves the displacement far less
// than the 1e-3 the test asks for (the measured error, 3e-5, is the nonlinear terms).
constexpr double kResidualTolerance = 1e-6;
constexpr int kMaxNonlinearIterations = 50;

// Dirichlet conditions: which degrees of freedom (3 * node + axis) are prescribed.
using FixedDofs = std::vector<bool>;

// The free-by-free block of K and the map from a dof to its free index (-1 if fixed).
struct FreeSystem {
  std::vector<int> free_index;
  std::vector<int> free_dofs;
  Eigen::SparseMatrix<double> K_ff;
};

FreeSystem restrict_to_free(const Eigen::SparseMatrix<double>& K, const FixedDofs& fixed) {
  FreeSystem system;
  system.free_index.assign(fixed.size(), -1);
  for (std::size_t dof = 0; dof < fixed.size(); ++dof) {
    if (fixed[dof]) continue;
    system.free_index[dof] = static_cast<int>(system.free_dofs.size());
    system.free_dofs.push_back(static_cast<int>(dof));
  }
  std::vector<Eigen::Triplet<double>> triplets;
  for (int col = 0; col < K.outerSize(); ++col)
    for (Eigen::SparseMatrix<double>::InnerIterator it(K, col); it; ++it) {
      const int i = system.free_index[it.row()], j = system.free_index[it.col()];
      if (i >= 0 && j >= 0) triplets.emplace_back(i, j, it.value());
    }
  const int n = static_cast<int>(system.free_dofs.size());
  system.K_ff.resize(n, n);
  system.K_ff.setFromTriplets(triplets.begin(), triplets.end());
  return system;
}

// Linear elasticity (frames of the rest state): the displacement u with u = u_prescribed on
// the fixed dofs and K u = f_ext on the free ones.
Eigen::VectorXd solve_linear(const Model& model, const FixedDofs& fixed,
                             const Eigen::VectorXd& u_prescribed, const Eigen::VectorXd& f_ext) {
  Eigen::VectorXd rest(model.dof_count());
  for (int n = 0; n < model.node_count(); ++n) rest.segment<3>(3 * n) = model.rest_positions[n];
  std::vector<Frame> frames;
  element_frames(model, rest, frames);
  const Eigen::SparseMatrix<double> K = assemble_element_stiffness(model, frames);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(model.dof_count());
  for (int dof = 0; dof < model.dof_count(); ++dof)
    if (fixed[dof]) u[dof] = u_prescribed[dof];
  const Eigen::VectorXd rhs_full = f_ext - K * u;
  const FreeSystem system = restrict_to_free(K, fixed);
  Eigen::VectorXd rhs(system.free_dofs.size());
  for (std::size_t i = 0; i < system.free_dofs.size(); ++i) rhs[i] = rhs_full[system.free_dofs[i]];
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(system.K_ff);
  EXPECT_EQ(ldlt.info(), Eigen::Success) << "LDLT of the free stiffness (linear solve)";
  const Eigen::VectorXd u_free = ldlt.solve(rhs);
  for (std::size_t i = 0; i < system.free_dofs.size(); ++i) u[system.free_dofs[i]] = u_free[i];
  return u;
}

struct NonlinearSolution {
  Eigen::VectorXd x;                 // positions
  int iterations = 0;
  double relative_residual = 0.0;    // |free part of f_ext + f_int| / |free part of f_ext|
  bool converged = false;
};

// The co-rotational equilibrium f_ext + f_int(x) = 0 on the free dofs, from `x_start` (whose
// fixed dofs are the prescribed positions).
NonlinearSolution solve_corotational(const Model& model, const FixedDofs& fixed,
                                     const Eigen::VectorXd& x_start, const Eigen::VectorXd& f_ext) {
  NonlinearSolution solution;
  solution.x = x_start;
  double load = 0.0;
  for (int dof = 0; dof < model.dof_count(); ++dof)
    if (!fixed[dof]) load += f_ext[dof] * f_ext[dof];
  load = std::sqrt(load);
  std::vector<Frame> frames;
  for (;;) {
    element_frames(model, solution.x, frames);
    Eigen::VectorXd residual = f_ext;
    add_element_forces(model, frames, solution.x, residual);
    const FreeSystem system = restrict_to_free(assemble_element_stiffness(model, frames), fixed);
    Eigen::VectorXd r(system.free_dofs.size());
    for (std::size_t i = 0; i < system.free_dofs.size(); ++i) r[i] = residual[system.free_dofs[i]];
    solution.relative_residual = r.norm() / load;
    if (solution.relative_residual <= kResidualTolerance) {
      solution.converged = true;
      return solution;
    }
    if (solution.iterations == kMaxNonlinearIterations) return solution;
    const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(system.K_ff);
    EXPECT_EQ(ldlt.info(), Eigen::Success) << "LDLT of the free tangent (co-rotational solve)";
    const Eigen::VectorXd dx = ldlt.solve(r);
    for (std::size_t i = 0; i < system.free_dofs.size(); ++i) solution.x[system.free_dofs[i]] += dx[i];
    ++solution.iterations;
  }
}

TEST(StaticTest, PatchTestReproducesALinearFieldInsideAJitteredBox) {
  // Any linear field u = A X + c imposed on the boundary is the exact solution (constant
  // strain, zero body force), so interior nodes must reproduce it: the patch test.
  const test::StructuredBox box = test::structured_box(Eigen::Vector3d(0.4, 0.3, 0.3), 4, 3, 3, 0.15);
  const Model model = make_model(box.mesh, Material{5000.0, 0.45, 1000.0});
  std::mt19937 random(7u);
  const Eigen::Matrix3d A = Eigen::Map<const Eigen::Matrix3d>(test::random_vector(random, 9, 1e-2).data());
  const Eigen::Vector3d c = test::random_vector(random, 3, 1e-3);
  Eigen::VectorXd exact(model.dof_count());
  FixedDofs fixed(model.dof_count(), false);
  int interior = 0;
  for (int n = 0; n < model.node_count(); ++n) {
    exact.segment<3>(3 * n) = A * model.rest_positions[n] + c;
    for (int axis = 0; axis < 3; ++axis) fixed[3 * n + axis] = box.on_boundary(n);
    interior += box.on_boundary(n) ? 0 : 1;
  }
  ASSERT_EQ(interior, 3 * 2 * 2) << "interior node count of the 4 x 3 x 3 box";
  const Eigen::VectorXd u =
      solve_linear(model, fixed, exact, Eigen::VectorXd::Zero(model.dof_count()));
  const double field_size = exact.lpNorm<Eigen::Infinity>();
  for (int n = 0; n < model.node_count(); ++n) {
    if (box.on_boundary(n)) continue;
    EXPECT_LE((u.segment<3>(3 * n) - exact.segment<3>(3 * n)).norm(),
              kLinearFieldTolerance * field_size)
        << "patch test: displacement of interior node " << n << " vs the linear field";
  }
}

TEST(StaticTest, BarInUniaxialTensionMatchesTheAnalyticSolution) {
  // A bar [0,L] x [0,b] x [0,c] on rollers (u_x = 0 on x = 0, u_y = 0 on y = 0, u_z = 0 on
  // z = 0: no rigid motion left, no lateral constraint), pulled by a uniform traction sigma
  // on x = L. Small-strain elasticity: u = (sigma x / E, -nu sigma y / E, -nu sigma z / E),
  // a linear field, so the discrete solution is exact on any mesh.
  const double L = 1.0, sigma = 200.0;
  const Material material{1e5, 0.3, 1000.0};
  const test::StructuredBox box = test::structured_box(Eigen::Vector3d(L, 0.2, 0.1), 10, 3, 2, 0.1);
  const Model model = make_model(box.mesh, material);
  FixedDofs fixed(model.dof_count(), false);
  for (int n = 0; n < model.node_count(); ++n)
    for (int axis = 0; axis < 3; ++axis) fixed[3 * n + axis] = box.on_face(n, axis, 0);
  const Eigen::VectorXd f = box.face_load(0, 1, Eigen::Vector3d(sigma, 0.0, 0.0));
  EXPECT_NEAR(f.sum(), sigma * 0.2 * 0.1, kLinearFieldTolerance * sigma * 0.2 * 0.1)
      << "total load on the end face vs sigma times its area";
  const Eigen::VectorXd u = solve_linear(model, fixed, Eigen::VectorXd::Zero(model.dof_count()), f);
  const double E = material.young_modulus, nu = material.poisson_ratio;
  const double elongation = sigma * L / E;
  for (int n = 0; n < model.node_count(); ++n) {
    const Eigen::Vector3d& X = model.rest_positions[n];
    const Eigen::Vector3d exact(sigma * X[0] / E, -nu * sigma * X[1] / E, -nu * sigma * X[2] / E);
    EXPECT_LE((u.segment<3>(3 * n) - exact).norm(), kLinearFieldTolerance * elongation)
        << "uniaxial bar: displacement of node " << n << " vs (sigma x, -nu sigma y, -nu sigma z) / E";
  }
}

// The cantilever: [0,L] x [0,b] x [0,b], clamped (u = 0) on x = 0, a shear load P in -z spread
// as a uniform traction over the end face x = L. E = 1e5 Pa, nu = 0.3.
struct Cantilever {
  static constexpr double L = 1.0;
  static constexpr double b = 0.1;
  static constexpr Material material{1e5, 0.3, 1000.0};

  // Timoshenko beam theory for an end-loaded cantilever:
  //   delta = P L^3 / (3 E I) + P L / (kappa G A),  I = b^4 / 12, A = b^2, G = E / (2 (1 + nu)),
  // with the shear coefficient kappa = 5/6 of a rectangle. Valid for a slender beam (L / b = 10
  // here, where the shear term is 0.8% of the bending term) in small strain; it ignores the
  // local 3D effects at the clamp (the clamped face also blocks the Poisson contraction) and
  // at the load (Saint-Venant), each a fraction of a percent of delta at this slenderness.
  static double timoshenko_deflection(double P) {
    const double E = material.young_modulus, nu = material.poisson_ratio;
    const double I = b * b * b * b / 12.0, A = b * b, G = E / (2.0 * (1.0 + nu));
    const double kappa = 5.0 / 6.0;
    return P * L * L * L / (3.0 * E * I) + P * L / (kappa * G * A);
  }

  explicit Cantilever(int n_across)
      : box(test::structured_box(Eigen::Vector3d(L, b, b), 10 * n_across, n_across, n_across)),
        model(make_model(box.mesh, material)),
        fixed(model.dof_count(), false) {
    for (int n = 0; n < model.node_count(); ++n)
      for (int axis = 0; axis < 3; ++axis) fixed[3 * n + axis] = box.on_face(n, 0, 0);
  }

  // Consistent nodal forces of the load P (in -z) on the end face.
  Eigen::VectorXd load(double P) const {
    return box.face_load(0, 1, Eigen::Vector3d(0.0, 0.0, -P / (b * b)));
  }

  test::StructuredBox box;
  Model model;
  FixedDofs fixed;
};

TEST(StaticTest, CantileverConvergesToTimoshenkoTheory) {
  // Tip deflection measured work-conjugately: delta_h = (f . u) / P, the mean deflection of
  // the end face weighted by the load (Timoshenko's plane sections deflect uniformly). It is
  // the compliance of the discrete beam, which converges from below (linear tetrahedra are
  // too stiff in bending) at O(h^2) asymptotically: the energy error of linear elements.
  //
  // Levels 20x2x2, 40x4x4, 80x8x8 hexahedra (h = 0.05, 0.025, 0.0125 m). The Kuhn split is
  // very stiff in bending with few elements through the thickness: the errors measured are
  // 0.78, 0.50, 0.21, 0.070 from 10x1x1 to 80x8x8, observed orders 0.65, 1.22, 1.60; so
  // the coarsest pair is still pre-asymptotic and 10x1x1 is left out. A level 160x16x16 would
  // take ~30 s in the direct solver.
  const double P = 1.0;
  const double analytic = Cantilever::timoshenko_deflection(P);
  constexpr int kLevels = 3;
  const int across[kLevels] = {2, 4, 8};   // hexahedra across the section; 10 times that along
  double deflection[kLevels], error[kLevels];
  for (int i = 0; i < kLevels; ++i) {
    const Cantilever beam(across[i]);
    const Eigen::VectorXd f = beam.load(P);
    const Eigen::VectorXd u =
        solve_linear(beam.model, beam.fixed, Eigen::VectorXd::Zero(beam.model.dof_count()), f);
    deflection[i] = f.dot(u) / P;
    error[i] = (analytic - deflection[i]) / analytic;
    std::printf("cantilever %dx%dx%d: tip deflection %.6g m, Timoshenko %.6g m, relative error %.4g\n",
                10 * across[i], across[i], across[i], deflection[i], analytic, error[i]);
  }
  // Too stiff, less so at each refinement.
  EXPECT_GT(error[0], error[1]) << "cantilever tip deflection error, 20x2x2 vs 40x4x4";
  EXPECT_GT(error[1], error[2]) << "cantilever tip deflection error, 40x4x4 vs 80x8x8";
  EXPECT_GT(error[2], 0.0) << "cantilever tip deflection error at 80x8x8 (compliance from below)";
  // Observed order between the two finest levels (measured 1.60): about 2 for linear
  // tetrahedra in bending, still approached from below here; [1.5, 2.5] tells O(h^2) from
  // O(h) (locking) and from a wrong analytic reference (which would bend the order away).
  const double order = std::log2(error[1] / error[2]);
  constexpr double kMinOrder = 1.5, kMaxOrder = 2.5;
  EXPECT_GE(order, kMinOrder) << "observed convergence order of the tip deflection";
  EXPECT_LE(order, kMaxOrder) << "observed convergence order of the tip deflection";
  // Richardson extrapolation of the two finest levels with the asymptotic order 2 (measured
  // 2.3% below Timoshenko: the pre-asymptotic order 1.6 < 2 makes it undershoot; Timoshenko
  // itself is good to a fraction of a percent here).
  const double richardson = (4.0 * deflection[2] - deflection[1]) / 3.0;
  const double richardson_error = (analytic - richardson) / analytic;
  std::printf("cantilever: observed order %.3f, Richardson (p = 2) %.6g m, relative error %.4g\n",
              order, richardson, richardson_error);
  constexpr double kExtrapolatedTolerance = 0.03;   // "a few percent"
  EXPECT_LE(std::abs(richardson_error), kExtrapolatedTolerance)
      << "relative error of the Richardson-extrapolated tip deflection";
  // The finest level alone (measured 7.0%).
  constexpr double kFinestTolerance = 0.10;
  EXPECT_LE(error[2], kFinestTolerance) << "relative tip deflection error at 80x8x8";
}

TEST(StaticTest, LargeRigidRotationOfTheCantileverIsSolvedByTheCorotationalFormulation) {
  // The cantilever's rest shape is left in place; its clamp is turned by Q (90 degrees about
  // a skew axis: the clamp nodes are prescribed at Q X) and the load turned to Q P. The exact
  // answer is the unturned solution turned: x = Q (X + u). For a small load (Timoshenko tip
  // deflection 1e-4 L; this coarse 20x2x2 mesh deflects half that) small-strain theory is
  // accurate, so x must be Q (X + u_small) to the neglected nonlinear terms, ~1e-4 relative
  // (measured 3e-5). Plain linear elasticity with the rest state's tangent
  // sees the turn as a huge strain and gets it badly wrong.
  const Cantilever beam(2);
  const Model& model = beam.model;
  const double P = 1e-4 * Cantilever::L / Cantilever::timoshenko_deflection(1.0);
  const Eigen::VectorXd f = beam.load(P);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model.dof_count());
  const Eigen::VectorXd u_small = solve_linear(model, beam.fixed, zero, f);
  const double u_size = u_small.lpNorm<Eigen::Infinity>();

  const Eigen::Matrix3d Q = test::rotation_about(Eigen::Vector3d(1.0, -2.0, 0.5), test::degrees(90.0));
  const Eigen::VectorXd rest = test::flat_positions(beam.box.mesh);
  const Eigen::VectorXd turned_rest = test::rigidly_moved(rest, Q, Eigen::Vector3d::Zero());
  const Eigen::VectorXd turned_load = test::rigidly_moved(f, Q, Eigen::Vector3d::Zero());
  const Eigen::VectorXd expected = test::rigidly_moved(rest + u_small, Q, Eigen::Vector3d::Zero());

  // Start from the turned rest shape: it satisfies the clamp and has no elastic force.
  const NonlinearSolution corotational = solve_corotational(model, beam.fixed, turned_rest, turned_load);
  ASSERT_TRUE(corotational.converged)
      << "co-rotational iteration: relative residual " << corotational.relative_residual
      << " after " << corotational.iterations << " iterations";
  const double corotational_error = (corotational.x - expected).lpNorm<Eigen::Infinity>() / u_size;

  // Plain linear elasticity: K of the rest state, the clamp displaced by (Q - I) X.
  const Eigen::VectorXd u_linear = solve_linear(model, beam.fixed, turned_rest - rest, turned_load);
  const double linear_error = (rest + u_linear - expected).lpNorm<Eigen::Infinity>() / u_size;
  std::printf("turned cantilever: co-rotational error %.3g (%d iterations), linear error %.3g "
              "(of the displacement size %.3g m)\n",
              corotational_error, corotational.iterations, linear_error, u_size);

  // Within 1e-3 of the displacement: the small-strain solution's own accuracy at this load,
  // with a margin. The linear error measured is ~2e4 (the turn, ~0.1 m, read as strain).
  constexpr double kSmallStrainTolerance = 1e-3;
  EXPECT_LE(corotational_error, kSmallStrainTolerance)
      << "co-rotational solution of the turned cantilever vs Q (X + u_small)";
  // The test can fail: the non-co-rotational answer must be far off.
  constexpr double kLinearFailureFactor = 10.0;
  EXPECT_GT(linear_error, kLinearFailureFactor * corotational_error)
      << "linear (rest-frame) solution error of the turned cantilever, vs the co-rotational one";
}

}  // namespace
}  // namespace sigmafem
