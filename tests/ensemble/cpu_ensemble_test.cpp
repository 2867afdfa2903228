// CpuEnsemble: each sigma point is the CPU reference with its own stiffnesses, and the
// re-sampling (Recentering) does what docs/ROUKF.md says.
#include "host/ensemble/cpu_ensemble.h"

#include <gtest/gtest.h>

#include <cmath>

#include "host/mesh/mesh_locate.h"
#include "host/mesh/observed_points.h"
#include "host/model/model.h"
#include "host/reference/reference_simulation.h"
#include "host/scenario/scenario.h"

namespace sigmafem {
namespace {

class CpuEnsembleTest : public ::testing::Test {
 protected:
  void SetUp() override {
    scenario_ = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box.json");
    model_ = make_model(scenario_);
  }
  Eigen::Vector3d so(int step) const {
    return scenario_.control.trajectory.position(step * scenario_.time.dt, scenario_.control.start);
  }
  Scenario scenario_;
  Model model_;
};

TEST_F(CpuEnsembleTest, EachSigmaPointIsTheReferenceWithItsStiffness) {
  const std::vector<int> estimated = {0, 2};
  // Jacobi, as the lone ReferenceSimulation: the same arithmetic, so the same bits.
  CpuEnsemble ensemble(model_, estimated, scenario_.observations.nodes, 3, 2, Preconditioner::jacobi);
  Eigen::MatrixXd theta(2, 3);
  theta << std::log(100.0), std::log(150.0), std::log(400.0),
           std::log(50.0), std::log(200.0), std::log(250.0);
  ensemble.set_parameters(theta);
  for (int k = 1; k <= 10; ++k) ensemble.advance(so(k));
  Eigen::MatrixXd y;
  ensemble.predicted_observations(y);
  for (int s = 0; s < 3; ++s) {
    ReferenceSimulation alone(model_);
    std::vector<double> stiffness = alone.ligament_stiffness();
    stiffness[0] = std::exp(theta(0, s));
    stiffness[2] = std::exp(theta(1, s));
    alone.set_ligament_stiffness(stiffness);
    for (int k = 1; k <= 10; ++k) alone.step(so(k));
    // Same arithmetic on a worker thread: the same bits.
    EXPECT_EQ(alone.positions(), ensemble.simulation(s).positions()) << "sigma point " << s;
    for (std::size_t o = 0; o < scenario_.observations.nodes.size(); ++o)
      EXPECT_EQ(Eigen::Vector3d(y.block(3 * static_cast<Eigen::Index>(o), s, 3, 1)),
                alone.node_position(scenario_.observations.nodes[o]))
          << "observation " << o << " of sigma point " << s;
  }
}

TEST_F(CpuEnsembleTest, ResultsDoNotDependOnTheThreadCount) {
  // Sigma points are taken by whichever thread comes free (host/common/worker_pool.h) and
  // their own factors are made again at different steps: each one's arithmetic is its own, so
  // one, two and three threads give the same bits.
  const std::vector<int> estimated = {0, 2};
  const int S = 5;
  Eigen::MatrixXd theta(2, S);
  for (int s = 0; s < S; ++s) {
    theta(0, s) = std::log(100.0 + 40.0 * s);
    theta(1, s) = std::log(300.0 - 30.0 * s);
  }
  std::vector<Eigen::MatrixXd> observed;
  for (int threads : {1, 2, 3}) {
    CpuEnsemble ensemble(model_, estimated, scenario_.observations.nodes, S, threads);
    ensemble.set_parameters(theta);
    for (int k = 1; k <= 12; ++k) ensemble.advance(so(k));
    Eigen::MatrixXd y;
    ensemble.predicted_observations(y);
    observed.push_back(y);
  }
  EXPECT_EQ(observed[0], observed[1]) << "one thread against two";
  EXPECT_EQ(observed[0], observed[2]) << "one thread against three";
}

// Observed points anywhere (host/mesh/observed_points.h): a point located at a node gives
// that node's position bit for bit; a point at a face's centre stays at the centre of the
// deformed face (the mean of its three nodes), and an interior point moves with its
// tetrahedron, at every step.
TEST_F(CpuEnsembleTest, ObservedPointsMoveWithTheirElements) {
  const Mesh& mesh = scenario_.mesh;
  const std::array<int, 4>& t = mesh.tetrahedra[100];
  const Eigen::Vector3d face_centre = (mesh.nodes[t[0]] + mesh.nodes[t[1]] + mesh.nodes[t[2]]) / 3.0;
  const Eigen::Vector3d interior =
      0.1 * mesh.nodes[t[0]] + 0.2 * mesh.nodes[t[1]] + 0.3 * mesh.nodes[t[2]] + 0.4 * mesh.nodes[t[3]];
  const int node = scenario_.observations.nodes[0];
  ObservedPoints points(std::vector<int>{node});
  for (const Eigen::Vector3d& p : {mesh.nodes[node], face_centre, interior})
    points.push_back(ObservedPoint::at(mesh, locate_point(mesh, p)));
  CpuEnsemble ensemble(model_, {0, 1, 2}, points, 2);
  Eigen::MatrixXd theta(3, 2);
  theta << std::log(100.0), std::log(300.0), std::log(80.0), std::log(200.0), std::log(300.0),
      std::log(50.0);
  ensemble.set_parameters(theta);
  Eigen::MatrixXd y;
  for (int k = 1; k <= 20; ++k) {
    ensemble.advance(so(k));
    ensemble.predicted_observations(y);
    for (int s = 0; s < 2; ++s) {
      const Eigen::VectorXd& x = ensemble.simulation(s).positions();
      auto at = [&](int n) { return Eigen::Vector3d(x.segment<3>(3 * n)); };
      const Eigen::Vector3d observed_at_node = y.block<3, 1>(3, s);
      EXPECT_EQ(observed_at_node, Eigen::Vector3d(y.block<3, 1>(0, s))) << "step " << k;
      EXPECT_LT((y.block<3, 1>(6, s) - (at(t[0]) + at(t[1]) + at(t[2])) / 3.0).norm(), 1e-14)
          << "face centre, step " << k;
      EXPECT_LT((y.block<3, 1>(9, s) -
                 (0.1 * at(t[0]) + 0.2 * at(t[1]) + 0.3 * at(t[2]) + 0.4 * at(t[3])))
                    .norm(),
                1e-14)
          << "interior point, step " << k;
    }
  }
  EXPECT_GT((y.block<3, 1>(6, 0) - face_centre).norm(), 1e-5) << "the organ moved";
}

TEST_F(CpuEnsembleTest, RecenteringResamplesAroundTheCorrectedMean) {
  const int S = 3;
  CpuEnsemble ensemble(model_, {1}, scenario_.observations.nodes, S);
  Eigen::MatrixXd theta(1, S);
  theta << std::log(100.0), std::log(300.0), std::log(900.0);
  ensemble.set_parameters(theta);
  for (int k = 1; k <= 20; ++k) ensemble.advance(so(k));
  Eigen::MatrixXd X(model_.dof_count(), S), V(model_.dof_count(), S);
  for (int s = 0; s < S; ++s) {
    X.col(s) = ensemble.simulation(s).positions();
    V.col(s) = ensemble.simulation(s).velocities();
  }
  Recentering r;
  r.alpha = 1.0 / S;
  r.directions = Eigen::MatrixXd(1, S);
  r.directions << -1.2, 0.0, 1.2;
  r.correction = Eigen::VectorXd::Constant(1, 0.3);
  r.factor = Eigen::MatrixXd::Constant(1, 1, 0.5);
  ensemble.recenter(r);
  const Eigen::VectorXd mean = X.rowwise().mean();
  const Eigen::VectorXd L = r.alpha * X * r.directions.transpose();
  const Eigen::VectorXd x_hat = mean + 0.3 * L;
  const Eigen::VectorXd Lv = r.alpha * V * r.directions.transpose();
  const Eigen::VectorXd v_hat = V.rowwise().mean() + 0.3 * Lv;
  ASSERT_GT(Lv.norm(), 1e-6 * v_hat.norm()) << "the sigma points' velocities differ";
  for (int s = 0; s < S; ++s) {
    const Eigen::VectorXd expected = x_hat + 0.5 * L * r.directions(0, s);
    EXPECT_LT((ensemble.simulation(s).positions() - expected).norm(), 1e-12 * expected.norm())
        << "re-sampled positions of sigma point " << s;
    const Eigen::VectorXd expected_velocity = v_hat + 0.5 * Lv * r.directions(0, s);
    EXPECT_LT((ensemble.simulation(s).velocities() - expected_velocity).norm(),
              1e-12 * (1.0 + expected_velocity.norm()))
        << "re-sampled velocities of sigma point " << s;
  }
}

// Factors (factorised_preconditioner.h), one per sigma point or one shared, change how each
// step's system is solved, not which: every sigma point follows Jacobi's trajectory to the CG
// tolerance, in a fraction of the iterations, and its bits do not depend on the thread count.
TEST_F(CpuEnsembleTest, FactorsFollowJacobiInAFractionOfTheIterations) {
  constexpr int S = 3, kSteps = 40;
  Eigen::MatrixXd theta(2, S);
  theta << std::log(100.0), std::log(150.0), std::log(400.0),
           std::log(50.0), std::log(200.0), std::log(250.0);
  CpuEnsemble jacobi(model_, {0, 2}, scenario_.observations.nodes, S, 2, Preconditioner::jacobi);
  CpuEnsemble own(model_, {0, 2}, scenario_.observations.nodes, S, 2, Preconditioner::factorised);
  CpuEnsemble shared(model_, {0, 2}, scenario_.observations.nodes, S, 2, Preconditioner::factorised);
  shared.set_own_factors_budget(0.0);
  CpuEnsemble one_thread(model_, {0, 2}, scenario_.observations.nodes, S, 1, Preconditioner::factorised);
  long jacobi_iterations = 0, own_iterations = 0, shared_iterations = 0;
  int own_reported = 0;   // the factorisations the step reports say were made
  for (CpuEnsemble* ensemble : {&jacobi, &own, &shared, &one_thread}) ensemble->set_parameters(theta);
  for (int k = 1; k <= kSteps; ++k) {
    for (int it : jacobi.advance(so(k)).cg_iterations) jacobi_iterations += it;
    const StepReport own_report = own.advance(so(k));
    for (int it : own_report.cg_iterations) own_iterations += it;
    own_reported += own_report.factorisations;
    for (int it : shared.advance(so(k)).cg_iterations) shared_iterations += it;
    one_thread.advance(so(k));
  }
  EXPECT_EQ(own_reported, own.factorisations());
  EXPECT_EQ(jacobi.factorisations(), 0);
  EXPECT_FALSE(own.shares_a_factor()) << "three factors of the box fit the default budget";
  EXPECT_TRUE(shared.shares_a_factor()) << "a zero budget";
  EXPECT_GE(own.factorisations(), S);
  EXPECT_LT(own.factorisations(), S * kSteps / 4) << "factors are kept over steps";
  EXPECT_GE(shared.factorisations(), 1);
  EXPECT_LT(shared.factorisations(), kSteps / 4) << "the factor is kept over steps";
  EXPECT_LE(10 * own_iterations, jacobi_iterations)
      << own_iterations << " iterations with own factors, " << jacobi_iterations << " Jacobi";
  EXPECT_LE(10 * shared_iterations, jacobi_iterations)
      << shared_iterations << " iterations with a shared factor, " << jacobi_iterations << " Jacobi";
  for (int s = 0; s < S; ++s) {
    const Eigen::VectorXd& x = jacobi.simulation(s).positions();
    Eigen::VectorXd displacement = x;
    for (int i = 0; i < model_.node_count(); ++i) displacement.segment<3>(3 * i) -= model_.rest_positions[i];
    // Each step's velocity change is solved to |r| <= 1e-10 |b| by both; 40 such errors,
    // amplified by at most the condition number (~1e3), stay below 1e-5 of the displacement.
    EXPECT_LE((x - own.simulation(s).positions()).norm(), 1e-5 * displacement.norm()) << "sigma point " << s;
    EXPECT_LE((x - shared.simulation(s).positions()).norm(), 1e-5 * displacement.norm()) << "sigma point " << s;
    EXPECT_EQ(own.simulation(s).positions(), one_thread.simulation(s).positions())
        << "sigma point " << s << ": thread count changed the bits";
  }
}

TEST_F(CpuEnsembleTest, RejectsWrongShapes) {
  CpuEnsemble ensemble(model_, {0, 1}, scenario_.observations.nodes, 3);
  EXPECT_THROW(ensemble.set_parameters(Eigen::MatrixXd::Zero(3, 3)), std::invalid_argument);
  EXPECT_THROW(CpuEnsemble(model_, {7}, scenario_.observations.nodes, 3), std::invalid_argument);
}

}  // namespace
}  // namespace sigmafem
