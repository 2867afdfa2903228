// Short estimations of the box and the liver keep their bits on every back end (issue 17: the
// kernels and the device ensembles are being rewritten around shared sources, and that must
// change no number). Each run's estimates (what estimates.csv prints: the step, every
// estimate, its std, the innovation RMS and NIS, the noise scale and the flags) are hashed and
// compared with tests/conformance/estimate_bits.txt, recorded on a machine named by a
// fingerprint per back end (the CPU's model, and the compiler and Eigen for the CPU back end,
// the OpenCL or Vulkan device's name and version for the others): the bits of float32 kernels
// compiled by PoCL or lavapipe for another CPU, or by another compiler, are not the same, so a
// machine with no record for its fingerprint skips (GTEST_SKIP, also under
// SIGMAFEM_TESTS_REQUIRE=all: that is not a missing requirement). The agreement of the back
// ends with the CPU reference is tested elsewhere (whole_run_test.cpp, ensemble_conformance).
// To record a machine's bits (after checking that a change is meant to move them):
//   SIGMAFEM_RECORD_BITS=1 build/tests/sigmafem_tests --gtest_filter='EstimateBits*'
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "filter/estimation.h"
#include "generated_data.h"
#include "host/engine/make_ensemble.h"
#include "host/model/model.h"
#include "host/opencl/opencl_device.h"
#include "host/scenario/scenario.h"
#include "host/vulkan/vulkan_device.h"
#include "requirement.h"
#include "tests/filter/scenario_filter_options.h"

namespace sigmafem {
namespace {

const char* const kRecordFile = SIGMAFEM_SOURCE_DIR "/tests/conformance/estimate_bits.txt";

// FNV-1a, 64 bits: enough to tell one run's bits from another's.
class BitHash {
 public:
  void add(const void* data, std::size_t size) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i) value_ = (value_ ^ bytes[i]) * 1099511628211ull;
  }
  void add(double x) { add(&x, sizeof x); }
  void add(int x) { add(&x, sizeof x); }
  void add(const Eigen::VectorXd& v) {
    for (Eigen::Index i = 0; i < v.size(); ++i) add(v[i]);
  }
  std::string hex() const {
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(value_));
    return text;
  }

 private:
  std::uint64_t value_ = 14695981039346656037ull;
};

std::string bits_cpu_model() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 1);
  return "unknown cpu";
}

// What the bits of a back end depend on besides the source, hashed; empty when the back end
// is not on this machine (`why` says so).
std::string bits_fingerprint(const std::string& backend, std::string* why) {
  std::string parts = bits_cpu_model();
  if (backend == "cpu") {
    parts += " | " __VERSION__ " | Eigen " + std::to_string(EIGEN_WORLD_VERSION) + "." +
             std::to_string(EIGEN_MAJOR_VERSION) + "." + std::to_string(EIGEN_MINOR_VERSION);
  } else if (backend == "opencl") {
    const auto devices = list_opencl_devices();
    if (devices.empty()) {
      *why = "no OpenCL platform on this machine";
      return "";
    }
    // The compute units too: the host may size the CG's work-groups by them.
    parts += " | " + devices[0].platform + " | " + devices[0].name + " | " + devices[0].version +
             " | " + std::to_string(devices[0].compute_units) + " units";
  } else {
    const auto devices = list_vulkan_devices(why);
    if (devices.empty()) return "";
    parts += " | " + devices[0].name + " | " + devices[0].api_version;
  }
  BitHash hash;
  hash.add(parts.data(), parts.size());
  return hash.hex();
}

// The hash of what estimates.csv prints for every step of the run.
std::string estimate_bits(const EstimationRun& run) {
  BitHash hash;
  for (const EstimationStep& step : run.steps) {
    hash.add(step.step);
    hash.add(step.time);
    hash.add(step.stiffness);
    hash.add(step.stiffness_std);
    hash.add(step.innovation_rms);
    hash.add(step.normalised_innovation);
    hash.add(step.noise_scale);
    hash.add(static_cast<int>(step.change_detected) + 2 * static_cast<int>(step.catching_up));
  }
  return hash.hex();
}

// Lines "FINGERPRINT CASE HASH" of the record file, keyed by "FINGERPRINT CASE".
std::map<std::string, std::string> read_bits_record() {
  std::map<std::string, std::string> record;
  std::ifstream in(kRecordFile);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string print, name, hash;
    if (fields >> print >> name >> hash) record[print + " " + name] = hash;
  }
  return record;
}

void write_bits_record(const std::map<std::string, std::string>& record) {
  const std::string temporary = std::string(kRecordFile) + ".tmp";
  {
    std::ofstream out(temporary);
    out << "# The bits of short estimations per machine fingerprint: "
           "tests/conformance/estimate_bits_test.cpp\n";
    for (const auto& [key, hash] : record) out << key << " " << hash << "\n";
  }
  std::filesystem::rename(temporary, kRecordFile);
}

struct BitsCase {
  std::string scenario;
  std::string backend;
};

// How ctest and gtest name a case: "box/cpu".
void PrintTo(const BitsCase& c, std::ostream* out) { *out << c.scenario << "/" << c.backend; }

class EstimateBits : public ::testing::TestWithParam<BitsCase> {};

TEST_P(EstimateBits, StayTheSameOnThisMachine) {
  const BitsCase& c = GetParam();
  std::string why;
  const std::string print = bits_fingerprint(c.backend, &why);
  if (print.empty()) SIGMAFEM_MISSING(why);
  Scenario s = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/" + c.scenario + ".json");
  // 40 steps with the cut at step 21: the estimates move fast from the prior, the cut and the
  // change response run, and every kernel of a filter step runs 40 times (about 4 s on
  // lavapipe on the 2-core machine).
  s.time.steps = 40;
  for (auto& event : s.events) event.time = 21 * s.time.dt;
  const ObservationTable data = test::generated_observations(s);
  const EstimationOptions options =
      test::filter_options(s, SigmaPointSet::simplex, s.filter->observation_std);
  // The devices' CG with Jacobi, as recorded (OpenCL's default on a CPU device is now its
  // shared factor: other bits, and OpenCL follows the CPU back end with it in WholeRun and
  // the conformance suite); the CPU back end with its default, the factors.
  DeviceOptions device;
  if (c.backend != "cpu") device.preconditioner = Preconditioner::jacobi;
  auto ensemble = make_ensemble(c.backend, make_model(s), s.filter->estimate, s.observations.nodes,
                                static_cast<int>(s.filter->estimate.size()) + 1, device);
  const EstimationRun run = run_estimation(*ensemble, options, data.times, data.so, data.points, {});
  ASSERT_TRUE(run.complete) << run.stop_reason;
  ASSERT_EQ(run.steps.size(), 40u);
  const std::string bits = estimate_bits(run);
  const std::string key = print + " " + c.scenario + "/" + c.backend;
  std::map<std::string, std::string> record = read_bits_record();
  if (std::getenv("SIGMAFEM_RECORD_BITS") != nullptr) {
    record[key] = bits;
    write_bits_record(record);
    std::cout << "recorded " << key << " " << bits << "\n";
    return;
  }
  const auto found = record.find(key);
  if (found == record.end())
    GTEST_SKIP() << "no bits recorded for " << c.scenario << "/" << c.backend
                 << " on this machine (fingerprint " << print << "); its hash is " << bits;
  EXPECT_EQ(bits, found->second) << c.scenario << " on " << c.backend
                                 << ": the estimates' bits moved";
}

std::string bits_case_name(const ::testing::TestParamInfo<BitsCase>& info) {
  std::string backend = info.param.backend == "cpu" ? "Cpu" : info.param.backend == "opencl" ? "OpenCl" : "Vulkan";
  std::string scenario = info.param.scenario;
  scenario[0] = static_cast<char>(std::toupper(scenario[0]));
  return scenario + backend;
}

INSTANTIATE_TEST_SUITE_P(BoxAndLiver, EstimateBits,
                         ::testing::Values(BitsCase{"box", "cpu"}, BitsCase{"box", "opencl"},
                                           BitsCase{"box", "vulkan"}, BitsCase{"liver", "cpu"},
                                           BitsCase{"liver", "opencl"}, BitsCase{"liver", "vulkan"}),
                         bits_case_name);

}  // namespace
}  // namespace sigmafem
