// The Truth Cube (issue 15, item 5): scenarios/truth_cube.json and its measured data
// (scenarios/truth_cube_data, made by scenarios/make_truth_cube.py from
// ../shared/data/truth-cube: 343 beads located by CT in a silicone cube at 0, 5, 12.5 and
// 18.25% nominal strain). The first data sigmafem did not make:
//   - the declared model (E = 15.3 kPa, nu = 0.45, bonded plates, the nominal plate travel)
//     follows most of the beads' motion, and is at rest at each scan (the scans are static);
//   - the beads cannot tell the modulus: with the plates imposing the displacement, the
//     static field does not depend on E (only on nu), so doubling E moves the beads by far
//     less than the model's error; no estimate of E from these beads can mean anything
//     (README, "The Truth Cube");
//   - the effects diagnose tried bring the beads nearer, without explaining them.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <iostream>
#include <sstream>
#include <string>

#include "host/data/observation_table.h"
#include "host/generator/generate.h"
#include "host/scenario/scenario.h"
#include "temp_path.h"

namespace sigmafem {
namespace {

const std::string kScenario = std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/truth_cube.json";
const std::string kMeasured = std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/truth_cube_data/observations.csv";

// Per compressed scan: the model's bead error against the measured beads (mean and largest,
// m), the measured displacement from the uncompressed scan (mean, m), and how far the model's
// beads moved in the step before the scan (largest, m: 0 when at rest).
struct ScanFigures {
  double mean_error = 0.0, max_error = 0.0, mean_displacement = 0.0, last_step_motion = 0.0;
};

// The scenario's model simulated noise-free by generate (with `inject`, effects the data get),
// against the measured beads at the scans (the rows after 0 where the beads are observed).
std::vector<ScanFigures> compare_with_beads(Scenario s, const std::vector<EffectValue>& inject = {}) {
  s.observations.noise_std = 0.0;
  const test::TempDir dir("sigmafem_truth_cube_test");
  GenerateOptions options;
  options.out_dir = dir.path();
  options.vtk_every = 0;
  options.inject = inject;
  std::ostringstream log;
  generate(s, options, log);
  const int points = static_cast<int>(s.observations.observed.size());
  const ObservationTable model = read_observations_csv(dir.file("observations.csv"), points, s.time.dt);
  const ObservationTable measured = read_observations_csv(kMeasured, points, s.time.dt);
  std::vector<ScanFigures> scans;
  for (int k = 1; k < measured.row_count(); ++k) {
    if (std::isnan(measured.points(k, 0))) continue;
    ScanFigures f;
    for (int p = 0; p < points; ++p) {
      const auto bead = [&](const ObservationTable& t, int row) -> Eigen::Vector3d {
        return t.points.row(row).segment<3>(3 * p).transpose();
      };
      const double error = (bead(model, k) - bead(measured, k)).norm();
      f.mean_error += error / points;
      f.max_error = std::max(f.max_error, error);
      f.mean_displacement += (bead(measured, k) - bead(measured, 0)).norm() / points;
      f.last_step_motion = std::max(f.last_step_motion, (bead(model, k) - bead(model, k - 1)).norm());
    }
    scans.push_back(f);
  }
  return scans;
}

const char* const kStrain[] = {"5%", "12.5%", "18.25%"};

TEST(TruthCube, TheDeclaredModelFollowsMostOfTheBeadsMotionAndIsAtRestAtEachScan) {
  const std::vector<ScanFigures> scans = compare_with_beads(load_scenario(kScenario));
  ASSERT_EQ(scans.size(), 3u) << "three compressed scans";
  for (std::size_t i = 0; i < scans.size(); ++i) {
    const ScanFigures& f = scans[i];
    std::cout << "truth cube, declared model, " << kStrain[i] << ": bead error mean " << 1e3 * f.mean_error
              << " mm, largest " << 1e3 * f.max_error << " mm; measured displacement mean "
              << 1e3 * f.mean_displacement << " mm; last step's motion " << 1e6 * f.last_step_motion << " um\n";
    // Most of the motion: the error under a quarter of the measured displacement (measured at
    // stop 35: 34%, 22% and 21% at 5, 12.5 and 18.25% strain; the bound is for the larger
    // strains, where a model that missed the compression would be off by the whole of it).
    if (i > 0) {
      EXPECT_LT(f.mean_error, 0.25 * f.mean_displacement) << kStrain[i];
    }
    EXPECT_LT(f.mean_error, 0.5 * f.mean_displacement) << kStrain[i];
    // At rest: the scans are static, and a model still moving would be judged mid-motion
    // (with nu = 0.49 and QR frames the cube drifts sideways by 24 um a step at 18.25%: below).
    EXPECT_LT(f.last_step_motion, 1e-6) << kStrain[i];
  }
}

// Near incompressibility the QR frame (SOFA's large method, the default) is not at rest at
// the 18.25% scan: at nu = 0.49 the cube drifted sideways by about 30 um a step (its elements'
// QR frames follow one edge, and their forces have a net torque: element_test.cpp). With the
// polar frame (material.rotation "polar") the same model is at rest at every scan.
TEST(TruthCube, NearIncompressibilityThePolarFrameIsAtRestWhereTheQrFrameDrifts) {
  Scenario s = load_scenario(kScenario);
  ASSERT_EQ(s.material.rotation, ElementRotation::polar) << "the scenario's own";
  s.material.poisson_ratio = 0.49;
  s.material.rotation = ElementRotation::qr;
  const std::vector<ScanFigures> qr = compare_with_beads(s);
  s.material.rotation = ElementRotation::polar;
  const std::vector<ScanFigures> polar = compare_with_beads(s);
  ASSERT_EQ(qr.size(), 3u);
  ASSERT_EQ(polar.size(), 3u);
  for (std::size_t i = 0; i < polar.size(); ++i) {
    std::cout << "truth cube, nu 0.49, " << kStrain[i] << ": last step's motion " << 1e6 * qr[i].last_step_motion
              << " um with the QR frame, " << 1e6 * polar[i].last_step_motion << " um with the polar frame; bead error mean "
              << 1e3 * qr[i].mean_error << " and " << 1e3 * polar[i].mean_error << " mm\n";
    EXPECT_LT(polar[i].last_step_motion, 1e-6) << kStrain[i];
  }
  EXPECT_GT(qr[2].last_step_motion, 1e-5) << "the QR frame is at rest at 18.25% too: nothing to mend";
}

// With plates of 1e5 N/m instead of 1e6 their give let the beads feel E a little (0.02 to
// 0.08 mm of the mean error); at 1e6 the change is 0.01 mm at most (stop 35).
TEST(TruthCube, TheBeadsCannotTellTheModulus) {
  Scenario stiffer = load_scenario(kScenario);
  const std::vector<ScanFigures> declared = compare_with_beads(stiffer);
  stiffer.material.young_modulus *= 2.0;
  // The same ligament and control springs: only the tissue is stiffer.
  const std::vector<ScanFigures> doubled = compare_with_beads(stiffer);
  ASSERT_EQ(declared.size(), doubled.size());
  for (std::size_t i = 0; i < declared.size(); ++i) {
    const double change = std::abs(doubled[i].mean_error - declared[i].mean_error);
    std::cout << "truth cube, " << kStrain[i] << ": bead error mean " << 1e3 * declared[i].mean_error
              << " mm with E, " << 1e3 * doubled[i].mean_error << " mm with 2E\n";
    EXPECT_LT(change, 0.02 * declared[i].mean_error) << kStrain[i] << ": the modulus would be observable";
  }
}

// The effects diagnose added on these beads (README, "The Truth Cube": a camera offset, a
// control scale, the plates' travel 13% beyond the nominal strain, and a lambda scale of 2.6,
// nu 0.48 for the declared 0.45), declared, bring the beads nearer at every strain, by at
// least a quarter (measured: 41%, 46% and 43%), the lambda scale by at least 3% of what the
// other two leave at 12.5 and 18.25% (measured: 7%, 10% and 9%); the outcome stays
// unexplained, with the cube's sideways bulge the model still lacks.
TEST(TruthCube, TheEffectsDiagnoseTriedBringTheBeadsNearer) {
  const Scenario s = load_scenario(kScenario);
  const std::vector<ScanFigures> declared = compare_with_beads(s);
  const std::vector<EffectValue> rigid_and_travel = {{"camera_offset", {0.000171, 0.000855, -0.000109}},
                                                     {"control_scale", {1.13}}};
  std::vector<EffectValue> all = rigid_and_travel;
  all.push_back({"lambda_scale", {2.6}});
  const std::vector<ScanFigures> without_lambda = compare_with_beads(s, rigid_and_travel);
  const std::vector<ScanFigures> with_effects = compare_with_beads(s, all);
  ASSERT_EQ(declared.size(), with_effects.size());
  ASSERT_EQ(declared.size(), without_lambda.size());
  for (std::size_t i = 0; i < declared.size(); ++i) {
    std::cout << "truth cube, " << kStrain[i] << ": bead error mean " << 1e3 * with_effects[i].mean_error
              << " mm, largest " << 1e3 * with_effects[i].max_error << " mm with the effects diagnose added ("
              << 1e3 * without_lambda[i].mean_error << " mm, largest " << 1e3 * without_lambda[i].max_error
              << " mm without the lambda scale)\n";
    EXPECT_LT(with_effects[i].mean_error, 0.75 * declared[i].mean_error) << kStrain[i];
    if (i > 0) {
      EXPECT_LT(with_effects[i].mean_error, 0.97 * without_lambda[i].mean_error) << kStrain[i];
    }
    // Still beyond what the beads' localisation noise alone leaves: 0.3 mm per axis (the
    // scenario's) has a mean length of 1.6 x 0.3 = 0.48 mm.
    EXPECT_GT(with_effects[i].mean_error, 0.48e-3) << kStrain[i] << ": within the beads' noise";
  }
}

}  // namespace
}  // namespace sigmafem
