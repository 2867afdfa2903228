// diagnose (host/diagnosis/diagnosis.h) on the box of scenarios/box_diagnose.json (200 steps,
// 0.5 mm noise, the coarse box): data with one candidate effect injected and not declared must be traced to
// that effect, its estimate within 10% of the injected value and the stiffness error down at
// least 5 times; clean data must stay consistent with nothing added (several seeds); data
// with an effect outside the library (a stiff inclusion) must be reported unexplained.
// Each whole diagnose runs about 11 filter runs of 200 steps (the declared model, 9
// candidates, the refined pass): about 5 s on the CPU back end with its own factor per sigma
// point (FindsGravity 5.4 s alone on the 2-core machine; 23 s with Jacobi CG, 11 s on OpenCL
// with PoCL; stop 31). They run in the Release pass only (setup.sh), like the other
// whole-estimation tests; the four liver cases at the end run on OpenCL.
#include "host/diagnosis/diagnosis.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "requirement.h"
#include "temp_path.h"
#include "host/common/input_error.h"
#include "host/generator/generate.h"
#include "host/opencl/opencl_device.h"
#include "host/scenario/effect_catalogue.h"

namespace sigmafem {
namespace {
namespace fs = std::filesystem;

TEST(EffectCatalogue, ParsesAndRejectsInjections) {
  const EffectValue g = parse_effect_assignment("gravity=0,-9.81,0", "--inject");
  EXPECT_EQ(g.name, "gravity");
  EXPECT_EQ(g.value, (std::vector<double>{0.0, -9.81, 0.0}));
  EXPECT_EQ(parse_effect_assignment("young_scale=1.5", "--inject").value, std::vector<double>{1.5});
  auto message = [](const std::string& text) {
    try {
      parse_effect_assignment(text, "--inject");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_NE(message("gravty=0,0,1").find("unknown effect \"gravty\""), std::string::npos) << message("gravty=0,0,1");
  EXPECT_NE(message("gravity=0,0").find("expects 3 numbers"), std::string::npos) << message("gravity=0,0");
  EXPECT_NE(message("gravity=0,x,1").find("\"x\" is not a number"), std::string::npos) << message("gravity=0,x,1");
  EXPECT_NE(message("young_scale=-2").find("must be > 0"), std::string::npos) << message("young_scale=-2");
  EXPECT_NE(message("camera_offset").find("expected NAME=VALUE"), std::string::npos) << message("camera_offset");
  EXPECT_EQ(message("camera_offset=1e-3,0,0"), "(no error)");
  EXPECT_NE(message("ligament_law=0").find("must be > 0"), std::string::npos) << message("ligament_law=0");
  EXPECT_NE(message("time_lag=-0.1").find("must be >= 0"), std::string::npos) << message("time_lag=-0.1");
  EXPECT_NE(message("damping_scale=1").find("expects 2 numbers"), std::string::npos) << message("damping_scale=1");
  // An extra ligament is placed at a region: named extra_ligament:REGION, never alone.
  EXPECT_NE(message("extra_ligament=100").find("extra_ligament:REGION"), std::string::npos)
      << message("extra_ligament=100");
  const EffectValue extra = parse_effect_assignment("extra_ligament:bottom=150", "--inject");
  EXPECT_EQ(extra.name, "extra_ligament:bottom");
  EXPECT_EQ(effect_family(extra.name), "extra_ligament");
  EXPECT_EQ(effect_region(extra.name), "bottom");
}

TEST(CandidateLibrary, AnExtraLigamentIsACandidateAtEveryRegion) {
  const Scenario scenario = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/box_diagnose.json");
  const std::vector<std::string> all = candidate_library(scenario, {});
  EXPECT_EQ(all, (std::vector<std::string>{"gravity", "young_scale", "lambda_scale", "camera_offset", "ligament_law",
                                           "extra_ligament:bottom", "extra_ligament:side_y0",
                                           "extra_ligament:side_y15", "time_lag", "damping_scale", "control_scale"}));
  EXPECT_EQ(candidate_library(scenario, {"extra_ligament:side_y0", "time_lag"}),
            (std::vector<std::string>{"extra_ligament:side_y0", "time_lag"}));
  try {
    candidate_library(scenario, {"extra_ligament:top"});
    ADD_FAILURE() << "a region the scenario lacks was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no candidate region \"top\""), std::string::npos) << e.what();
  }
  EXPECT_THROW(candidate_library(scenario, {"inclusion"}), InputError);
}

TEST(EffectCatalogue, TheStiffInclusionIsNotACandidate) {
  const EffectDefinition* inclusion = find_effect("inclusion");
  ASSERT_NE(inclusion, nullptr);
  EXPECT_FALSE(inclusion->candidate);
  EXPECT_EQ(effect_names(true).find("inclusion"), std::string::npos);
}

struct BoxData {
  Scenario scenario;
  ObservationTable data;
  std::optional<TruthTable> truth;
  std::optional<PointCloudTable> cloud;   // when the scenario observes a surface cloud
};

// Data from `generate` on scenarios/SCENARIO.json; `steps` > 0 shortens the run, and
// `truth_refine` > 0 simulates the truth on the mesh refined that many levels.
BoxData box_data(const std::vector<EffectValue>& inject, std::uint64_t seed = 1,
                 const std::string& scenario = "box_diagnose", int steps = 0, int truth_refine = 0) {
  BoxData box;
  box.scenario = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/" + scenario + ".json");
  if (steps > 0) box.scenario.time.steps = steps;
  const fs::path dir = test::unique_temp_path("sigmafem_diagnosis_test");
  GenerateOptions options;
  options.out_dir = dir.string();
  options.vtk_every = 0;
  options.seed = seed;
  options.inject = inject;
  if (truth_refine > 0) options.truth_mesh.refine = truth_refine;
  std::ostringstream log;
  generate(box.scenario, options, log);
  box.data = read_observations_csv((dir / "observations.csv").string(),
                                   static_cast<int>(box.scenario.observations.nodes.size()), box.scenario.time.dt);
  box.truth = read_truth_csv((dir / "truth.csv").string());
  if (box.scenario.observations.surface_cloud) box.cloud = read_point_cloud_csv((dir / "pointcloud.csv").string());
  fs::remove_all(dir);
  return box;
}

TEST(DiagnoseLikelihood, FitsAreComparedOnTheStepsNoneIsCatchingUp) {
  // Two complete fits of 6 steps, catching up on steps 1-2 and 2-3, and one that stopped after
  // 2 steps while catching up on step 0: the union leaves out 1-3 (the stopped fit adds
  // nothing), and each sum skips them.
  auto fit = [](std::vector<double> ll, std::vector<int> catching_up, bool complete) {
    ModelFit f;
    f.run.complete = complete;
    f.step_log_likelihood = ll;
    f.run.steps.resize(ll.size());
    for (int k : catching_up) f.run.steps[static_cast<std::size_t>(k)].catching_up = true;
    return f;
  };
  const ModelFit a = fit({1, 2, 4, 8, 16, 32}, {1, 2}, true);
  const ModelFit b = fit({-1, -2, -4, -8, -16, -32}, {2, 3}, true);
  const ModelFit stopped = fit({100, 200}, {0}, false);
  const std::vector<bool> left_out = catch_up_union({&a, &b, &stopped});
  EXPECT_EQ(left_out, std::vector<bool>({false, true, true, true, false, false}));
  EXPECT_EQ(log_likelihood_outside(a, left_out), 1 + 16 + 32);
  EXPECT_EQ(log_likelihood_outside(b, left_out), -(1 + 16 + 32));
  EXPECT_EQ(log_likelihood_outside(stopped, left_out), 100);
  EXPECT_EQ(log_likelihood_outside(a, {}), 63) << "nothing left out";
}

TEST(DiagnoseRefit, StartsFromTheFirstPassWithACutLigamentAtItsStiffnessBeforeTheCut) {
  // Three log-stiffnesses and one effect coordinate; the middle ligament found cut (held at a
  // millionth of its 307 N/m, no std left).
  ModelFit first;
  first.theta = Eigen::Vector4d(std::log(150.0), std::log(307e-6), std::log(200.0), 0.4);
  first.theta_std = Eigen::Vector4d(0.01, 0.0, 0.02, 0.001);
  first.run.cuts.push_back({1, 1051, 10.51, 307.0, 29.0});
  const RefitStart start = refit_start(first);
  EXPECT_DOUBLE_EQ(start.theta[0], first.theta[0]);
  EXPECT_DOUBLE_EQ(start.theta[1], std::log(307.0)) << "the refit runs through the steps before the cut";
  EXPECT_DOUBLE_EQ(start.theta[3], 0.4);
  EXPECT_DOUBLE_EQ(start.std[0], 0.1);
  EXPECT_DOUBLE_EQ(start.std[1], 0.05);
  EXPECT_DOUBLE_EQ(start.std[2], 0.2);
  EXPECT_DOUBLE_EQ(start.std[3], 0.05);
}

TEST(DiagnoseMisfit, SharesOfTheDeclaredModelsExcessNisAlongThePath) {
  // Mean NIS 136, 66, 61 against 36 rows: excess 100, 30, 25. The first effect removed 70% of
  // the declared model's excess, the second 5%, and 25% remains.
  auto fit = [](double nis_mean) {
    ModelFit f;
    f.residual.nis.mean = nis_mean;
    f.residual.nis.mean_dof = 36.0;
    return f;
  };
  const ModelFit declared = fit(136.0), first = fit(66.0), second = fit(61.0);
  const MisfitShares shares = misfit_shares({&declared, &first, &second});
  EXPECT_DOUBLE_EQ(shares.declared_excess, 100.0);
  ASSERT_EQ(shares.removed.size(), 2u);
  EXPECT_NEAR(shares.removed[0], 0.70, 1e-12);
  EXPECT_NEAR(shares.removed[1], 0.05, 1e-12);
  EXPECT_NEAR(shares.remaining, 0.25, 1e-12);
  // An effect that raised the NIS removed a negative share; shares and remainder add to 1.
  const ModelFit worse = fit(71.0);
  const MisfitShares back = misfit_shares({&declared, &first, &worse});
  EXPECT_NEAR(back.removed[1], -0.05, 1e-12);
  EXPECT_NEAR(back.removed[0] + back.removed[1] + back.remaining, 1.0, 1e-12);
  // A declared model with no excess has no shares to give (NaN, written as null).
  const ModelFit consistent = fit(35.0);
  const MisfitShares none = misfit_shares({&consistent, &first});
  EXPECT_TRUE(std::isnan(none.removed[0]));
  EXPECT_TRUE(std::isnan(none.remaining));
  EXPECT_EQ(misfit_shares({}).removed.size(), 0u);
}

std::string describe_residual(const ModelFit& fit) {
  std::ostringstream out;
  for (const DiagnosticTest& test : fit.residual.verdict.tests)
    if (!test.passed) out << "\n  " << test.name << ": " << test.detail;
  return out.str();
}

std::string describe(const Diagnosis& d) {
  std::ostringstream out;
  out << to_string(d.outcome) << ": " << d.conclusion << "\n";
  for (const DiagnosisRound& r : d.rounds)
    for (const CandidateScore& c : r.candidates)
      out << "  candidate " << c.effect << " score " << c.score << " residual with it " << to_string(c.verdict) << "\n";
  return out.str();
}

bool opencl_missing() { return list_opencl_devices().empty(); }

// Injects `effect`, runs diagnose with every candidate, and checks the three claims.
// `steps` > 0 shortens the scenario's run.
void expect_found(const EffectValue& effect, const std::vector<std::string>& candidates = {},
                  const std::string& scenario = "box_diagnose", const std::string& backend = "cpu",
                  std::uint64_t seed = 1, int steps = 0) {
  const BoxData box = box_data({effect}, seed, scenario, steps);
  DiagnoseOptions options;
  options.candidates = candidates;
  options.backend = backend;
  if (box.cloud) options.surface_cloud = &*box.cloud;
  const Diagnosis d = diagnose(box.scenario, box.data, box.truth, options);
  ASSERT_EQ(d.outcome, DiagnosisOutcome::explained) << describe(d);
  ASSERT_EQ(d.after().estimates.size(), 1u) << describe(d);
  const EffectEstimate& e = d.after().estimates[0];
  EXPECT_EQ(e.name, effect.name) << describe(d);
  // Within 10% of the injected value (as a vector), or within 3 of the stated std per axis.
  double error2 = 0.0, norm2 = 0.0;
  bool within_std = true;
  for (std::size_t j = 0; j < effect.value.size(); ++j) {
    error2 += std::pow(e.value[j] - effect.value[j], 2);
    norm2 += std::pow(effect.value[j], 2);
    within_std = within_std && std::abs(e.value[j] - effect.value[j]) <= 3.0 * e.std[j];
  }
  const double relative = std::sqrt(error2 / norm2);
  ::testing::Test::RecordProperty("effect_relative_error", std::to_string(relative));
  EXPECT_TRUE(relative <= 0.1 || within_std) << "estimate off by " << 100 * relative << "%: " << describe(d);
  // Each number left its prior for the truth: nearer the injected value than the prior's
  // median, in the coordinate the filter estimates (the log for a factor, a lag, a stiffness).
  // Every injected value but a zero component of a vector (gravity's x below) lies away from
  // its median, so an estimate that stayed at its prior (a widened std covers that too) fails.
  const EffectDefinition& definition = *find_effect(effect.name);
  for (std::size_t j = 0; j < effect.value.size(); ++j) {
    const EffectParameter& parameter = definition.parameters[j];
    auto coordinate = [&](double v) { return parameter.log ? std::log(v) : v; };
    const double from_truth = std::abs(coordinate(e.value[j]) - coordinate(effect.value[j]));
    if (coordinate(effect.value[j]) == parameter.prior_mean) continue;   // a zero component of a vector
    const double from_median = std::abs(coordinate(e.value[j]) - parameter.prior_mean);
    EXPECT_LT(from_truth, from_median) << parameter.name << " = " << e.value[j] << " +- " << e.std[j] << " for "
                                       << effect.value[j] << ": it stayed near its prior: " << describe(d);
  }
  ASSERT_TRUE(d.before().stiffness_error && d.after().stiffness_error);
  const double before = *d.before().stiffness_error, after = *d.after().stiffness_error;
  ::testing::Test::RecordProperty("stiffness_error_before", std::to_string(before));
  ::testing::Test::RecordProperty("stiffness_error_after", std::to_string(after));
  std::cout << effect.name << ": estimate off by " << 100 * relative << "%, stiffness error " << before << " -> "
            << after << " N/m\n";
  EXPECT_GE(before, 5.0 * after) << describe(d);
  EXPECT_EQ(d.discovered.size(), 1u);
}

TEST(DiagnoseBox, FindsACameraOffset) { expect_found({"camera_offset", {1e-3, -0.5e-3, 0.5e-3}}); }

TEST(DiagnoseBox, FindsGravity) { expect_found({"gravity", {0.0, -1.0, -1.5}}); }

TEST(DiagnoseBox, FindsAYoungModulusScale) {
  // Without the gravity candidate: on this quasi-static box the declared gravity (2 m/s^2) is
  // the only known force and the SO prescribes displacement, so a modulus scaled by s and a
  // gravity scaled by 1/s (with every ligament scaled by s) give the same observations.
  // Measured with every candidate: gravity (0.014, -0.004, -1.29) m/s^2 added, i.e. 3.29 =
  // 2 / 0.6 in all, score 104532 against young_scale's 104507; the report then says both
  // make the residual consistent.
  expect_found({"young_scale", {0.6}}, {"young_scale", "camera_offset"});
}

// The material nearer incompressible than declared (nu 0.45 -> 0.48; by hand also s = 3 on
// seed 2, 3.03 +- 0.046, and s = 0.5, nu 0.29, on seeds 1 and 3: 0.497 and 0.523, all
// explained with every candidate).
TEST(DiagnoseBox, FindsALambdaScale) { expect_found({"lambda_scale", {3.0}}); }

TEST(DiagnoseBox, FindsANonlinearLigamentLaw) { expect_found({"ligament_law", {0.005}}); }

TEST(DiagnoseBox, FindsAnExtraLigamentAtItsRegion) {
  // Named with its region: the two other regions are candidates too.
  expect_found({"extra_ligament:bottom", {150.0}});
}

TEST(DiagnoseBox, FindsATimeLag) { expect_found({"time_lag", {0.1}}); }

TEST(DiagnoseBox, FindsADampingMismatch) {
  // Both factors away from their prior median of 1, in opposite directions. The mass
  // coefficient is weakly observable on this slow pull: measured 2.64 +- 0.66 for 3 (the
  // stiffness one 0.503 +- 0.003 for 0.5; OpenCL, stop 30; 2.63 on the CPU reference), so the vector is 12% off and the check per number
  // is within 3 std; that it left its prior for the truth is checked above.
  expect_found({"damping_scale", {3.0, 0.5}});
}

TEST(DiagnoseBox, CleanDataAddNothing) {
  // No false discovery: the verdict is consistent and nothing is scored or added.
  for (std::uint64_t seed : {1u, 2u, 3u}) {
    const BoxData box = box_data({}, seed);
    const Diagnosis d = diagnose(box.scenario, box.data, box.truth, {});
    EXPECT_EQ(d.outcome, DiagnosisOutcome::consistent) << "seed " << seed << ": " << describe(d);
    EXPECT_TRUE(d.discovered.empty());
    EXPECT_EQ(d.fits.size(), 1u) << "no candidate was run";
  }
}

TEST(DiagnoseBox, AStiffInclusionStaysUnexplained) {
  // Young's modulus 5 times higher in a sphere of 6 cm radius at the box's centre: not in the
  // library. The report must not claim a library effect.
  // One round, not three, to keep the test short: measured with three, the later rounds add
  // nothing either (README), and the claims are decided on the first effect.
  const BoxData box = box_data({{"inclusion", {0.15, 0.075, 0.075, 0.06, 5.0}}});
  DiagnoseOptions options;
  options.max_rounds = 1;
  const Diagnosis d = diagnose(box.scenario, box.data, box.truth, options);
  EXPECT_EQ(d.outcome, DiagnosisOutcome::unexplained) << describe(d);
  EXPECT_TRUE(d.discovered.empty()) << describe(d);
  EXPECT_NE(d.conclusion.find("unexplained"), std::string::npos) << d.conclusion;
  // What the effects tried account for is said, and part of the misfit remains.
  EXPECT_NE(d.conclusion.find("% remains"), std::string::npos) << d.conclusion;
  EXPECT_GT(d.misfit.remaining, 0.0) << d.conclusion;
  ASSERT_FALSE(d.claims.empty()) << d.conclusion;
  std::cout << "stiff inclusion: " << d.claims[0].effect << " not claimed: " << d.claims[0].reason << "\n";
}

// A truth simulated on the box refined once (8 times the tetrahedra; the observed points at
// the same material points, the springs spread over the refined nodes of their attachments,
// host/generator/spring_spread.h): the data carry a model-form error no effect of the library
// removes, so the residual never turns consistent (host/diagnosis/model_form_claim.h). One
// round with three candidates, to keep each case near 25 s: the claims are decided on the
// first effect.
Diagnosis diagnose_refined_truth(const std::vector<EffectValue>& inject) {
  const BoxData box = box_data(inject, 1, "box_diagnose", 0, 1);
  DiagnoseOptions options;
  options.candidates = {"gravity", "camera_offset", "young_scale"};
  options.max_rounds = 1;
  return diagnose(box.scenario, box.data, box.truth, options);
}

TEST(DiagnoseBox, ATruthFromTheRefinedMeshWithAFullGravityClaimsTheGravityAlone) {
  const std::vector<double> g = {4.005, -8.01, 4.005};   // 9.81 m/s^2, oblique, undeclared
  const Diagnosis d = diagnose_refined_truth({{"gravity", g}});
  ASSERT_EQ(d.outcome, DiagnosisOutcome::partly_explained) << describe(d);
  ASSERT_EQ(d.discovered.size(), 1u) << describe(d);
  EXPECT_EQ(d.discovered[0].name, "gravity");
  const Eigen::Vector3d truth(g[0], g[1], g[2]);
  const Eigen::Vector3d found(d.discovered[0].value[0], d.discovered[0].value[1], d.discovered[0].value[2]);
  const double degrees = std::acos(std::clamp(found.normalized().dot(truth.normalized()), -1.0, 1.0)) * 180.0 / M_PI;
  std::cout << "refined truth, gravity: found " << found.transpose() << " (" << degrees << " degrees off, |g| "
            << found.norm() << "), stiffness error " << *d.before().stiffness_error << " -> "
            << *d.after().stiffness_error << " N/m\n";
  // Within 10% as a vector (measured (4.21, -8.26, 3.95): 3.4%, 1.1 degrees, |g| 2.7% high,
  // the refined box sagging a little more than the coarse model). With the springs kept on the
  // coarse nodes (--truth-springs nodes: point loads that the refined mesh makes softer, and
  // softer again at each level) |g| came out at 13.0 m/s^2, 33% high.
  EXPECT_LT((found - truth).norm(), 0.1 * truth.norm()) << describe(d);
  EXPECT_LT(degrees, 5.0) << describe(d);
  ASSERT_TRUE(d.before().stiffness_error && d.after().stiffness_error);
  EXPECT_GE(*d.before().stiffness_error, 5.0 * *d.after().stiffness_error) << describe(d);
  // The report says what remains.
  EXPECT_GT(d.misfit.remaining, 0.0);
  EXPECT_NE(d.conclusion.find("remains"), std::string::npos) << d.conclusion;
}

TEST(DiagnoseBox, ATruthFromTheRefinedMeshClaimsNoWrongEffect) {
  // Clean, and with an undeclared 3.9 mm camera offset. Clean, a gravity of 0.16 m/s^2 takes up
  // 52.6% of the refined mesh's misfit, far from zero in its own std but a small part of a
  // gravity's full size, so it is not claimed; with the offset a gravity scores 90% of the
  // offset's score and is not tried beside it (one round). Whatever the data cannot tell apart
  // is not claimed. (With --truth-springs nodes a gravity along the declared one and a softer
  // modulus took up the point loads' larger sag, scores 17111 and 16368.)
  for (const std::vector<EffectValue>& inject :
       {std::vector<EffectValue>{}, std::vector<EffectValue>{{"camera_offset", {3e-3, -2e-3, 1.5e-3}}}}) {
    const Diagnosis d = diagnose_refined_truth(inject);
    EXPECT_NE(d.outcome, DiagnosisOutcome::consistent) << "the model-form error is there: " << describe(d);
    for (const EffectValue& claimed : d.discovered)
      EXPECT_TRUE(!inject.empty() && claimed.name == inject[0].name) << "claimed " << claimed.name << ": " << describe(d);
    ASSERT_FALSE(d.claims.empty()) << describe(d);
    std::cout << "refined truth, " << (inject.empty() ? "clean" : inject[0].name) << ": " << to_string(d.outcome)
              << "; first checked " << d.claims[0].effect << " (" << (d.claims[0].claimed ? "claimed" : d.claims[0].reason)
              << ")\n";
  }
}

// The liver (scenarios/liver_diagnose.json: 300 steps, its six automatic surface regions) on
// the OpenCL back end, float32: the effects a device estimates are found there as on the CPU.
// Each diagnose is about 12 filter runs of 1 s.
TEST(DiagnoseLiverOnOpenCl, FindsAnExtraLigamentAmongTheSurfaceRegions) {
  if (opencl_missing()) SIGMAFEM_MISSING("no OpenCL platform on this machine");
  // Among all six regions and the two effects that also move the whole surface (a load, a
  // rigid offset); the whole library is the box tests' (DiagnoseBox). Until stop 41 the whole
  // library here too: 15 filter runs, 43 s on a fresh machine, the longest diagnosis test.
  expect_found({"extra_ligament:surface_5", {250.0}},
               {"gravity", "camera_offset", "extra_ligament:surface_1", "extra_ligament:surface_2",
                "extra_ligament:surface_3", "extra_ligament:surface_4", "extra_ligament:surface_5",
                "extra_ligament:surface_6"},
               "liver_diagnose", "opencl");
}

TEST(DiagnoseLiverOnOpenCl, FindsATimeLag) {
  // A physics effect the device kernels take per sigma point (step_constants.h).
  if (opencl_missing()) SIGMAFEM_MISSING("no OpenCL platform on this machine");
  // Against the effects that also shift the organ's response (a load, a rigid offset): the
  // whole library is the box tests' (DiagnoseBox); here 5 filter runs instead of 15 keep CI short.
  expect_found({"time_lag", {0.1}}, {"gravity", "camera_offset", "time_lag"}, "liver_diagnose", "opencl");
}

TEST(DiagnoseLiverOnOpenCl, CleanDataAddNothing) {
  if (opencl_missing()) SIGMAFEM_MISSING("no OpenCL platform on this machine");
  const BoxData liver = box_data({}, 1, "liver_diagnose");
  DiagnoseOptions options;
  options.backend = "opencl";
  const Diagnosis d = diagnose(liver.scenario, liver.data, liver.truth, options);
  EXPECT_EQ(d.outcome, DiagnosisOutcome::consistent) << describe(d);
  EXPECT_EQ(d.fits.size(), 1u);
}

// Surface point clouds (issue 15, item 4; scenarios/liver_cloud.json: 300 points per frame on
// the front third, 0.5 mm noise), the first 400 steps, on the CPU back end: a camera offset of
// 3 mm across the view moves the cloud off the surface, and diagnose finds it as on tracked
// points; clean data add nothing. Seed 11, a seed no figure was tuned on. By hand (stop 35,
// `sigmafem generate scenarios/liver_cloud.json --inject camera_offset=...` over 600 steps,
// then `sigmafem diagnose` with the whole library, 53 s a run): 3 mm along x (seed 1), y
// (seed 2) and the view (z, seed 3) explained, each component within 0.013 mm; clean seeds 1
// and 2 consistent; (2, -2, 1) mm with 5% outliers and 10% dropouts (seed 4) partly explained
// (the offset within 0.02 mm, the outliers that pass the gate leave the NIS high). The
// candidates here are those that also move the observed surface as a whole or in time
// (gravity, the modulus, the lag) and the offset: 6 filter runs instead of 15 keep CI short.
TEST(DiagnoseLiverCloud, FindsAThreeMillimetreCameraOffset) {
  expect_found({"camera_offset", {3e-3, 0.0, 0.0}}, {"gravity", "young_scale", "camera_offset", "time_lag"},
               "liver_cloud", "cpu", 11, 400);
}

TEST(DiagnoseLiverCloud, CleanDataAddNothing) {
  const BoxData liver = box_data({}, 11, "liver_cloud", 400);
  DiagnoseOptions options;
  options.surface_cloud = &*liver.cloud;
  const Diagnosis d = diagnose(liver.scenario, liver.data, liver.truth, options);
  EXPECT_EQ(d.outcome, DiagnosisOutcome::consistent) << describe(d);
  EXPECT_EQ(d.fits.size(), 1u);
}

}  // namespace
}  // namespace sigmafem

namespace sigmafem {
namespace {

// Issue 13, item 1, on the shipped liver (2000 steps, the cut at 10 s, 0.5 mm noise) with a
// full-size gravity the scenario does not declare (9.81 m/s^2, oblique): the declared model's
// filter drove every stiffness out of 1e-6..1e9 N/m (the bound then) by step 42 before the adaptive observation
// noise (filter/adaptive_noise.h). Now it runs to the end, keeps the stiffnesses within a factor
// of 3 of their prior medians (300, 600, 400 N/m: nothing it could learn from data it cannot
// explain) and calls its residual inconsistent; the gravity candidate's fit explains the data
// far better, finds the gravity and is consistent, and so is the true model (the gravity
// declared).
// On the CPU back end (its sparse factors): 31 s alone on the 2-core machine, where OpenCL on
// PoCL took 58 s (stop 32); the device ensembles are the other DiagnoseLiverOnOpenCl tests'.
TEST(DiagnoseLiver, TheDeclaredModelCompletesUnderAnUndeclaredLag) {
  // A 0.1 s tracking lag on the shipped liver, its first 400 steps. The parameter-change test
  // (filter/parameter_change_test.h) fired at step 57 on the left ligament, still at 0.86 of
  // its prior std, opened it by the prior std five times by step 123, and the declared
  // model's filter diverged (1.2e9 N/m at step 131-137, stop 38). A parameter the data have
  // not yet taught is not tested, and the adaptive noise's engaging keeps the test off.
  const BoxData liver = box_data({{"time_lag", {0.1}}}, 1, "liver", 400);
  DiagnoseOptions options;
  options.backend = "cpu";
  const ModelFit declared = fit_model(liver.scenario, liver.data, liver.truth, {}, options);
  ASSERT_TRUE(declared.run.complete) << declared.run.stop_reason;
  EXPECT_EQ(declared.residual.verdict.consistency, Consistency::inconsistent);
  for (const auto& change : declared.run.parameter_changes)
    EXPECT_GE(change.step, 100) << "a change taken while the filter was still learning";
}

TEST(DiagnoseLiver, TheDeclaredModelCompletesUnderAnUndeclaredFullGravity) {
  const BoxData liver = box_data({{"gravity", {4.005, -8.01, 4.005}}}, 1, "liver");
  DiagnoseOptions options;
  options.backend = "cpu";
  const ModelFit declared = fit_model(liver.scenario, liver.data, liver.truth, {}, options);
  ASSERT_TRUE(declared.run.complete) << declared.run.stop_reason;
  EXPECT_EQ(declared.run.steps.size(), 2000u);
  EXPECT_EQ(declared.residual.verdict.consistency, Consistency::inconsistent);
  EXPECT_GT(declared.run.noise_scaled_steps, 1500) << "the adaptive noise engaged";
  const double prior[] = {300.0, 600.0, 400.0};
  for (const EstimationStep& step : declared.run.steps)
    for (int j = 0; j < 3; ++j) {
      ASSERT_GT(step.stiffness[j], prior[j] / 3.0) << "step " << step.step << " ligament " << j;
      ASSERT_LT(step.stiffness[j], prior[j] * 3.0) << "step " << step.step << " ligament " << j;
    }
  const ModelFit gravity = fit_model(liver.scenario, liver.data, liver.truth, {"gravity"}, options);
  EXPECT_GT(gravity.log_likelihood - declared.log_likelihood, 1e7);
  EXPECT_LT(gravity.innovation_rms, 1e-3) << "the declared model's is " << declared.innovation_rms;
  ASSERT_EQ(gravity.estimates.size(), 1u);
  const Eigen::Vector3d g(4.005, -8.01, 4.005);
  EXPECT_LT((Eigen::Vector3d(gravity.estimates[0].value.data()) - g).norm(), 0.01 * g.norm())
      << "the gravity candidate finds the gravity within 1%";
  // And explains the data, so diagnose can claim it: the cut is caught up with while the
  // gravity is held (Roukf::hold_constants). Opened and corrected there as the stiffnesses
  // are, g_y went to -9.15 m/s^2 and the residual stayed biased (docs/ROUKF.md).
  EXPECT_GT(gravity.run.catch_up_steps, 0) << "the cut is detected in the gravity fit too";
  EXPECT_EQ(gravity.residual.verdict.consistency, Consistency::consistent) << describe_residual(gravity);
  // The stated std (first-order times the path's Birge ratio, filter/path_consistency.h)
  // bounds the error: within 5 of it per component. The first-order std alone was 5.5-8.2 off
  // before the catch-up waited for the innovations' mean (docs/ROUKF.md).
  const EffectEstimate& estimate = gravity.estimates[0];
  for (int j = 0; j < 3; ++j) {
    EXPECT_GE(estimate.std[j], estimate.first_order_std[j]);
    EXPECT_LE(std::abs(estimate.value[j] - g[j]), 5.0 * estimate.std[j])
        << "g_" << j << " = " << estimate.value[j] << " +- " << estimate.std[j] << " (first-order "
        << estimate.first_order_std[j] << ", path ratio " << estimate.path_ratio[j] << ")";
  }

  // The true model, the gravity declared, as `estimate` runs it (the scenario's simplex set,
  // 10% burn-in): consistent. It needs the velocities re-sampled (a rigid residual bias of
  // 0.052 mm with positions only), the catch-up after the cut left out of the tests (mean NIS
  // about 2000 for 100 steps after it) and the one-sided whiteness tests (the drift's lag-1
  // correlation of -0.029): docs/ROUKF.md.
  Scenario true_model = liver.scenario;
  true_model.gravity = g;
  options.sigma_points.reset();
  options.burn_in_fraction = 0.1;
  const ModelFit truth = fit_model(true_model, liver.data, liver.truth, {}, options);
  ASSERT_TRUE(truth.run.complete) << truth.run.stop_reason;
  EXPECT_EQ(truth.residual.verdict.consistency, Consistency::consistent) << describe_residual(truth);
  EXPECT_GT(truth.run.catch_up_steps, 0) << "the cut is detected and caught up with";
  EXPECT_LE(truth.run.catch_up_steps, 300);

  // Both fits find the middle ligament (parameter 1), and only it, cut after the cut at step
  // 1000 (filter/ligament_cut.h). Followed down in log space it held about 1 N/m to the end,
  // a force under the sag that the true model's residual kept as a translation (t 2.5) and
  // the gravity fit took up: 3.6-5.8 first-order std off on this seed, 1.6-3.9 with the cut.
  for (const ModelFit* fit : {&gravity, &truth}) {
    ASSERT_EQ(fit->run.cuts.size(), 1u);
    EXPECT_EQ(fit->run.cuts[0].parameter, 1);
    EXPECT_GT(fit->run.cuts[0].step, 1000);
    EXPECT_LT(fit->run.cuts[0].step, 1300);
  }
}

// Issue 13, item 4: data from a finer discretisation than the model's (the shipped liver's
// truth on its mesh refined once; the springs at the same nodes). The coarse model is off by
// 0.3-1 mm RMS (0.5 mm noise), a persistent error that the ligaments partly absorb, so the
// adaptive noise rarely engages and the NIS stays at 1.3-2.2 per degree of freedom. The change
// detector took that level for a cut (steps 177 and 228), opened the covariance, and the right
// ligament ran from 7e3 to 1e9 N/m by step 250: the filter stopped as diverged. Now the detector
// tests for a jump of the level over a reference that is itself beyond its band (F test,
// filter/change_detector.h): nothing fires, the filter completes, and the residual is called
// inconsistent. 400 of the 2000 steps (no cut): about 25 s to generate on the refined mesh.
TEST(DiagnoseLiver, TheDeclaredModelCompletesOnATruthFromAFinerMesh) {
  const BoxData liver = box_data({}, 1, "liver", 400, 1);
  // Both sets: diagnose's star and `estimate`'s simplex (the scenario's).
  for (const SigmaPointSet set : {SigmaPointSet::star, SigmaPointSet::simplex}) {
    DiagnoseOptions options;
    options.sigma_points = set;
    const ModelFit declared = fit_model(liver.scenario, liver.data, liver.truth, {}, options);
    ASSERT_TRUE(declared.run.complete) << to_string(set) << ": " << declared.run.stop_reason;
    EXPECT_EQ(declared.run.steps.size(), 400u);
    EXPECT_EQ(declared.run.changes_detected, 0) << to_string(set) << ": the model error's level is not a change";
    EXPECT_EQ(declared.residual.verdict.consistency, Consistency::inconsistent) << to_string(set);
  }
}

}  // namespace
}  // namespace sigmafem
