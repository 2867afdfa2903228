// VulkanFactorSolve (kernels/vulkan/factor_solve.comp): z = M^-1 r on the device against the
// same factor's substitutions on the host in double precision, cut into many dispatches or
// few, in both forms of the shader; the diagonal stand-in, and the factor in its place; a
// factor that no dispatch could hold; and the ensemble that uses it by default on a CPU device.
#include "host/vulkan/vulkan_factor_solve.h"

#include <Eigen/SparseCholesky>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "host/model/model.h"
#include "host/reference/reference_simulation.h"
#include "host/reference/spring_correction.h"
#include "host/scenario/scenario.h"
#include "host/vulkan/vulkan_ensemble.h"
#include "requirement.h"

namespace sigmafem {
namespace {

// A device with CG's buffers for a solve of S sigma points in Real (float or double): r
// uploaded, z, the active flags (every sigma point iterating but `inactive`), and CG's d and
// r.z, which the solve may finish (d_before and rz_before uploaded).
template <typename Real>
struct SolveBuffers {
  SolveBuffers(const std::vector<Real>& r, int S, int inactive, bool texel_reads)
      : device(0, sizeof(Real) == sizeof(double) ? Precision::double_precision : Precision::single),
        bytes(r.size() * sizeof(Real)),
        r_buffer(device.buffer(bytes, "r")),
        z_buffer(device.buffer(bytes, "z")),
        active(device.buffer(4 * static_cast<std::size_t>(S), "active")),
        d_buffer(device.buffer(bytes, "d")),
        rz_buffer(device.buffer(sizeof(Real) * static_cast<std::size_t>(S), "rz")),
        d_before(r.size()),
        rz_before(static_cast<std::size_t>(S)) {
    device.set_texel_reads(texel_reads);
    std::vector<std::uint32_t> flags(static_cast<std::size_t>(S), 1u);
    if (inactive >= 0) flags[static_cast<std::size_t>(inactive)] = 0u;
    device.upload(r_buffer, r.data(), bytes);
    device.upload(active, flags.data(), 4 * flags.size());
    for (std::size_t i = 0; i < d_before.size(); ++i) d_before[i] = static_cast<Real>(std::cos(0.21 * static_cast<double>(i)));
    for (int s = 0; s < S; ++s) rz_before[static_cast<std::size_t>(s)] = static_cast<Real>(1 + s);
    device.upload(d_buffer, d_before.data(), bytes);
    device.upload(rz_buffer, rz_before.data(), sizeof(Real) * rz_before.size());
  }
  std::vector<Real> read(const VulkanBuffer& buffer, std::size_t count) {
    std::vector<Real> values(count);
    device.download(buffer, values.data(), count * sizeof(Real));
    return values;
  }
  // z after the solve recorded.
  std::vector<Real> z() { return read(z_buffer, bytes / sizeof(Real)); }
  VulkanFactorSolve::CgBuffers cg() const { return {r_buffer, z_buffer, d_buffer, active, rz_buffer}; }
  VulkanDevice device;
  std::size_t bytes;
  VulkanBuffer r_buffer, z_buffer, active, d_buffer, rz_buffer;
  std::vector<Real> d_before, rz_before;
};

class VulkanFactorSolveTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    if (list_vulkan_devices(&why).empty()) SIGMAFEM_MISSING(why);
    load("box");
  }

  // The scenario's system at rest, its factor and its estimated ligaments' rows.
  void load(const std::string& name) {
    const Scenario scenario = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/" + name + ".json");
    const Model model = make_model(scenario);
    A_ = ReferenceSimulation(model).system_matrix();
    ASSERT_TRUE(factor_.factorise(A_));
    n_ = static_cast<int>(A_.rows());
    spring_rows_ = estimated_spring_rows(model, scenario.filter->estimate);
  }

  // Sigma point s's own springs at the estimated ligaments' rows: the factor's plus delta.
  Eigen::VectorXd spring_delta(int s) const {
    Eigen::VectorXd delta(static_cast<Eigen::Index>(spring_rows_.size()));
    for (Eigen::Index j = 0; j < delta.size(); ++j)
      delta[j] = 0.05 * A_.coeff(spring_rows_[static_cast<std::size_t>(j)], spring_rows_[static_cast<std::size_t>(j)]) *
                 (1.0 + s + 0.1 * static_cast<double>(j % 5));
    return delta;
  }

  // Each sigma point's coupling H for spring_delta(s) ([(s m + j) m + k]), of a prepared correction.
  std::vector<double> couplings(const SpringCorrection& correction, int S) const {
    const std::size_t m = spring_rows_.size();
    std::vector<double> values;
    for (int s = 0; s < S; ++s) {
      const Eigen::MatrixXd H = correction.coupling(spring_delta(s));
      for (std::size_t j = 0; j < m; ++j)
        for (std::size_t k = 0; k < m; ++k) values.push_back(H(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(k)));
    }
    return values;
  }

  // Sigma point s's own system A + E Delta_s E^T solved for b by Eigen's LDL^T in double.
  Eigen::VectorXd own_solve(int s, const Eigen::VectorXd& b) const {
    Eigen::SparseMatrix<double> own = A_;
    const Eigen::VectorXd delta = spring_delta(s);
    for (std::size_t j = 0; j < spring_rows_.size(); ++j)
      own.coeffRef(spring_rows_[j], spring_rows_[j]) += delta[static_cast<Eigen::Index>(j)];
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(own);
    EXPECT_EQ(solver.info(), Eigen::Success);
    return solver.solve(b);
  }

  // z of S sigma points ([row S + s]) for r, on device 0 in float32, with sigma point
  // `inactive` left alone (its z stays at `untouched`).
  // With `springs`, each sigma point's correction for spring_delta(s).
  // With `finish` (SF_FACTOR_FINISH_*), CG's d and r.z after it in *d and *rz; without
  // `stores_z` the solve is made without z (z stays at `untouched`).
  std::vector<float> device_solve(const std::vector<float>& r, int S, int inactive, bool texel_reads,
                                  long long loop_turns, bool diagonal, int* dispatches = nullptr,
                                  bool springs = false, int* split = nullptr, bool* shared = nullptr,
                                  std::uint32_t finish = SF_FACTOR_FINISH_NONE, std::vector<float>* d = nullptr,
                                  std::vector<float>* rz = nullptr, bool stores_z = true) {
    SolveBuffers<float> buffers(r, S, inactive, texel_reads);
    VulkanDevice& device = buffers.device;
    const std::vector<float> sentinel(r.size(), untouched);
    device.upload(buffers.z_buffer, sentinel.data(), buffers.bytes);
    SpringCorrection correction(springs ? spring_rows_ : std::vector<int>{});
    VulkanFactorSolve::CgBuffers cg = buffers.cg();
    if (!stores_z) cg.z = VulkanBuffer{};
    VulkanFactorSolve solve(device, n_, correction.size(), S, cg, loop_turns);
    if (diagonal)
      solve.upload_diagonal(A_);
    else
      solve.upload(factor_);
    if (springs) {
      correction.prepare(factor_);
      if (!solve.upload_springs(correction)) ADD_FAILURE() << "the correction does not fit a dispatch";
      couplings_ = couplings(correction, S);
    }
    if (dispatches) *dispatches = solve.dispatches();
    if (split) *split = solve.split();
    if (shared) *shared = solve.shared();
    VkCommandBuffer cmd = device.begin();
    if (springs) {
      solve.record_couplings(cmd, couplings_);
      device.barrier(cmd);
    }
    solve.record(cmd, finish);
    device.submit_and_wait(cmd);
    if (d) *d = buffers.read(buffers.d_buffer, r.size());
    if (rz) *rz = buffers.read(buffers.rz_buffer, static_cast<std::size_t>(S));
    return buffers.z();
  }

  // Sigma point s's r, a smooth field with a different phase each.
  std::vector<float> residuals(int S) const {
    std::vector<float> r(static_cast<std::size_t>(n_) * S);
    for (int i = 0; i < n_; ++i)
      for (int s = 0; s < S; ++s) r[static_cast<std::size_t>(i) * S + s] = static_cast<float>(std::sin(0.37 * i + s));
    return r;
  }

  static constexpr float untouched = 7.0f;
  Eigen::SparseMatrix<double> A_;
  FactorisedPreconditioner factor_;
  int n_ = 0;
  std::vector<int> spring_rows_;   // the box's estimated ligaments' rows
  std::vector<double> couplings_;  // each sigma point's H for spring_delta(s)
};

// Against P^T L^-T L^-1 P r in double from the same L, for S = 11 (a group of 8 and one of
// 3) and 9 (one of 8 and one whose only sigma point is done), and S = 4, 3 and 1; on a device
// with subgroup shuffles, at S = 11 and 9 the groups' lanes read the blocks together
// (factor_solve_shared: lanes past S and done sigma points take part), at 4, 3 and 1 a block
// row is shared by 2, 2 and 8 lanes (factor_solve_split); in short dispatches and in the
// default's few, texel and storage reads: within float32's rounding, the same bits however the
// solve is cut (into more than 20 dispatches by 1000 turns, or 150 where a turn is a chunk of
// 8 blocks), an inactive sigma point untouched.
TEST_F(VulkanFactorSolveTest, SolvesAsTheHostFactorInManyDispatchesOrFew) {
  const Eigen::SparseMatrix<double>& L = factor_.lower();
  const VulkanDeviceInfo info = list_vulkan_devices().front();
  for (const int S : {11, 9, 4, 3, 1}) {
    SCOPED_TRACE("S = " + std::to_string(S));
    const int inactive = S == 9 ? 8 : S > 1 ? S / 2 : -1;
    const std::vector<float> r = residuals(S);
    for (const bool texel_reads : {true, false}) {
      int many = 0, few = 0, split = 0;
      bool shared = false;
      // The shared reads turn once a chunk of 8 blocks: a smaller bound cuts as often.
      const long long cut_turns = VulkanFactorSolve::shares_blocks(info, S) ? 150 : 1000;
      const std::vector<float> cut =
          device_solve(r, S, inactive, texel_reads, cut_turns, false, &many, false, &split, &shared);
      const std::vector<float> whole = device_solve(r, S, inactive, texel_reads, kFactorLoopTurns, false, &few);
      EXPECT_EQ(split, VulkanFactorSolve::split_lanes(info, S));
      EXPECT_EQ(shared, VulkanFactorSolve::shares_blocks(info, S));
      if (info.subgroup_shuffle && info.subgroup_size >= 8) {
        EXPECT_EQ(split, S >= 9 ? 1 : S == 1 ? 8 : 2);
        EXPECT_EQ(shared, S >= 9);
      }
      EXPECT_GT(many, 20) << cut_turns << " loop turns cut the box's factor into many dispatches";
      EXPECT_LT(few, many);
      EXPECT_EQ(0, std::memcmp(cut.data(), whole.data(), cut.size() * sizeof(float)))
          << "the same sums in the same order, however the solve is cut";
      for (int s = 0; s < S; ++s) {
        Eigen::VectorXd y(n_);
        for (int i = 0; i < n_; ++i) y[factor_.order()[i]] = r[static_cast<std::size_t>(i) * S + s];
        L.triangularView<Eigen::Lower>().solveInPlace(y);
        L.transpose().triangularView<Eigen::Upper>().solveInPlace(y);
        const double scale = y.cwiseAbs().maxCoeff();
        for (int i = 0; i < n_; ++i) {
          const float got = cut[static_cast<std::size_t>(i) * S + s];
          if (s == inactive)
            ASSERT_EQ(got, untouched) << "row " << i;
          else
            ASSERT_NEAR(got, y[factor_.order()[i]], 1e-4 * scale) << "sigma point " << s << ", row " << i;
        }
      }
    }
  }
}

// Lanes a sigma point: a power of 2 within 8 lanes and the subgroup, where shuffles are.
TEST(VulkanFactorSolveSplit, LanesASigmaPointFillTheGroupAndTheSubgroup) {
  VulkanDeviceInfo info;
  info.subgroup_shuffle = true;
  info.subgroup_size = 8;
  EXPECT_EQ(VulkanFactorSolve::split_lanes(info, 1), 8);
  EXPECT_EQ(VulkanFactorSolve::split_lanes(info, 2), 4);
  EXPECT_EQ(VulkanFactorSolve::split_lanes(info, 3), 2);
  EXPECT_EQ(VulkanFactorSolve::split_lanes(info, 4), 2);
  EXPECT_EQ(VulkanFactorSolve::split_lanes(info, 5), 1);
  EXPECT_EQ(VulkanFactorSolve::split_lanes(info, 16), 1);
  info.subgroup_size = 4;   // SSE's lavapipe
  EXPECT_EQ(VulkanFactorSolve::split_lanes(info, 1), 4);
  EXPECT_EQ(VulkanFactorSolve::split_lanes(info, 3), 1);
  info.subgroup_size = 32;  // a GPU's: the group stays within kLanes
  EXPECT_EQ(VulkanFactorSolve::split_lanes(info, 1), 8);
  info.subgroup_shuffle = false;
  EXPECT_EQ(VulkanFactorSolve::split_lanes(info, 1), 1);
}

// The shared block reads: groups of 8 in one subgroup with shuffles, where the split is 1.
TEST(VulkanFactorSolveShared, GroupsOfEightReadTheBlocksTogetherWhereNoSplitIs) {
  VulkanDeviceInfo info;
  info.subgroup_shuffle = true;
  info.subgroup_size = 8;
  EXPECT_FALSE(VulkanFactorSolve::shares_blocks(info, 4));   // the split's
  EXPECT_TRUE(VulkanFactorSolve::shares_blocks(info, 5));
  EXPECT_TRUE(VulkanFactorSolve::shares_blocks(info, 16));
  info.subgroup_size = 32;
  EXPECT_TRUE(VulkanFactorSolve::shares_blocks(info, 64));
  info.subgroup_size = 4;   // SSE's lavapipe: a group of 8 would be two subgroups
  EXPECT_FALSE(VulkanFactorSolve::shares_blocks(info, 16));
  info.subgroup_size = 8;
  info.subgroup_shuffle = false;
  EXPECT_FALSE(VulkanFactorSolve::shares_blocks(info, 16));
}

// The solve finishing CG's step (SF_FACTOR_FINISH_*): at the start r.z and d = z, in an
// iteration r.z, beta = r.z / the last r.z and d = z + beta d, against the host's sums of the
// device's z; the same bits however the solve is cut (the partial r.z kept between dispatches:
// 150 turns cut the box's solve into tens, 3000 with its springs' correction, which needs a
// dispatch of m + 5); an inactive sigma point's d and r.z untouched. S = 11 (the shared reads on
// lavapipe), 4 (the split), 3; without a finish d and r.z stay as they were. A solve made
// without z (the ensemble's) gives the same d and r.z, its z left alone, and refuses to record
// without a finish.
TEST_F(VulkanFactorSolveTest, ItFinishesCgsStartAndDirection) {
  for (const int S : {11, 4, 3})
  for (const bool springs : {false, true}) {
    const int inactive = S / 2;
    const std::vector<float> r = residuals(S);
    const std::size_t size = r.size();
    for (const std::uint32_t finish : {SF_FACTOR_FINISH_NONE, SF_FACTOR_FINISH_START, SF_FACTOR_FINISH_DIRECTION}) {
      SCOPED_TRACE("S = " + std::to_string(S) + (springs ? ", springs" : "") + ", finish " + std::to_string(finish));
      std::vector<float> d_cut, rz_cut, d, rz;
      int many = 0;
      const std::vector<float> z_cut = device_solve(r, S, inactive, true, springs ? 3000 : 150, false, &many, springs,
                                                    nullptr, nullptr, finish, &d_cut, &rz_cut);
      const std::vector<float> z = device_solve(r, S, inactive, true, kFactorLoopTurns, false, nullptr, springs,
                                                nullptr, nullptr, finish, &d, &rz);
      EXPECT_GT(many, 2);
      EXPECT_EQ(0, std::memcmp(z_cut.data(), z.data(), size * sizeof(float)));
      EXPECT_EQ(0, std::memcmp(d_cut.data(), d.data(), size * sizeof(float)));
      EXPECT_EQ(0, std::memcmp(rz_cut.data(), rz.data(), static_cast<std::size_t>(S) * sizeof(float)));
      if (finish == SF_FACTOR_FINISH_NONE) {
        EXPECT_THROW(device_solve(r, S, inactive, true, kFactorLoopTurns, false, nullptr, springs, nullptr, nullptr,
                                  finish, nullptr, nullptr, false),
                     std::logic_error);
      } else {
        std::vector<float> d_no_z, rz_no_z;
        const std::vector<float> no_z = device_solve(r, S, inactive, true, kFactorLoopTurns, false, nullptr, springs,
                                                     nullptr, nullptr, finish, &d_no_z, &rz_no_z, false);
        EXPECT_EQ(0, std::memcmp(d_no_z.data(), d.data(), size * sizeof(float)));
        EXPECT_EQ(0, std::memcmp(rz_no_z.data(), rz.data(), static_cast<std::size_t>(S) * sizeof(float)));
        EXPECT_TRUE(std::all_of(no_z.begin(), no_z.end(), [](float v) { return v == untouched; }));
      }
      for (int s = 0; s < S; ++s) {
        const float rz_before = static_cast<float>(1 + s);
        double sum = 0.0;
        for (int i = 0; i < n_; ++i) {
          const std::size_t at = static_cast<std::size_t>(i) * S + s;
          sum += static_cast<double>(r[at]) * z[at];
        }
        const bool untouched_here = finish == SF_FACTOR_FINISH_NONE || s == inactive;
        if (untouched_here) {
          EXPECT_EQ(rz[static_cast<std::size_t>(s)], rz_before) << "sigma point " << s;
        } else {
          EXPECT_NEAR(rz[static_cast<std::size_t>(s)], sum, 1e-5 * std::abs(sum)) << "sigma point " << s;
        }
        const double beta = static_cast<double>(rz[static_cast<std::size_t>(s)]) / rz_before;
        for (int i = 0; i < n_; ++i) {
          const std::size_t at = static_cast<std::size_t>(i) * S + s;
          const float d_before = static_cast<float>(std::cos(0.21 * static_cast<double>(at)));
          if (untouched_here)
            ASSERT_EQ(d[at], d_before) << "sigma point " << s << ", row " << i;
          else if (finish == SF_FACTOR_FINISH_START)
            ASSERT_EQ(d[at], z[at]) << "sigma point " << s << ", row " << i;
          else
            ASSERT_NEAR(d[at], z[at] + beta * d_before, 1e-5 * (std::abs(z[at]) + std::abs(beta * d_before)))
                << "sigma point " << s << ", row " << i;
        }
      }
    }
  }
}

// With each sigma point's springs corrected between the substitutions (SpringCorrection): the
// solve with its own system A + E Delta_s E^T, against Eigen's LDL^T of that system in double,
// in 1000-turn dispatches and in the default's few (the same bits); on the box (about 35
// spring rows reaching 700 of its 1209: a correction of about 49 000 loop turns) and the
// liver (27 reaching 258 of 543), at S = 4 and 1 (its sums shared by 2 and 8 lanes where the
// device has subgroup shuffles) and S = 5 (a lane a sigma point).
TEST_F(VulkanFactorSolveTest, TheSpringCorrectionSolvesEachSigmaPointsOwnSystem) {
  for (const char* scenario : {"box", "liver"}) {
    for (const int S : {4, 1, 5}) {
      SCOPED_TRACE(std::string(scenario) + ", S = " + std::to_string(S));
      load(scenario);
      ASSERT_FALSE(spring_rows_.empty());
      const std::vector<float> r = residuals(S);
      int many = 0, few = 0;
      const std::vector<float> cut = device_solve(r, S, -1, true, 1000, false, &many, true);
      const std::vector<float> whole = device_solve(r, S, -1, true, kFactorLoopTurns, false, &few, true);
      EXPECT_GT(many, few);
      EXPECT_EQ(0, std::memcmp(cut.data(), whole.data(), cut.size() * sizeof(float)));
      for (int s = 0; s < S; ++s) {
        Eigen::VectorXd b(n_), uncorrected(n_);
        for (int i = 0; i < n_; ++i) b[i] = r[static_cast<std::size_t>(i) * S + s];
        const Eigen::VectorXd x = own_solve(s, b);
        factor_(b, uncorrected);
        const double scale = x.cwiseAbs().maxCoeff();
        EXPECT_GT((uncorrected - x).cwiseAbs().maxCoeff(), 1e-2 * scale)
            << "the springs change the solve: the correction is tested";
        for (int i = 0; i < n_; ++i)
          ASSERT_NEAR(whole[static_cast<std::size_t>(i) * S + s], x[i], 1e-4 * scale)
              << "sigma point " << s << ", row " << i;
      }
    }
  }
}

// In float64 (dvec4 storage buffers, and at S = 4 the split's shuffles of doubles), with the
// springs' correction: each sigma point's own system solved to float64's rounding, against
// Eigen's LDL^T of it, at S = 4 (2 lanes a sigma point where shuffles are) and 5 (one).
TEST_F(VulkanFactorSolveTest, InFloat64EachSigmaPointsOwnSystemToItsRounding) {
  if (!list_vulkan_devices().front().has_fp64) GTEST_SKIP() << "device 0 has no shaderFloat64";
  load("liver");
  for (const int S : {4, 5}) {
    SCOPED_TRACE("S = " + std::to_string(S));
    std::vector<double> r(static_cast<std::size_t>(n_) * S);
    for (int i = 0; i < n_; ++i)
      for (int s = 0; s < S; ++s) r[static_cast<std::size_t>(i) * S + s] = std::sin(0.37 * i + s);
    SolveBuffers<double> buffers(r, S, -1, true);
    VulkanDevice& device = buffers.device;
    SpringCorrection correction(spring_rows_);
    VulkanFactorSolve solve(device, n_, correction.size(), S, buffers.cg(), kFactorLoopTurns);
    solve.upload(factor_);
    correction.prepare(factor_);
    ASSERT_TRUE(solve.upload_springs(correction));
    VkCommandBuffer cmd = device.begin();
    solve.record_couplings(cmd, couplings(correction, S));
    device.barrier(cmd);
    solve.record(cmd);
    device.submit_and_wait(cmd);
    const std::vector<double> z = buffers.z();
    for (int s = 0; s < S; ++s) {
      Eigen::VectorXd b(n_);
      for (int i = 0; i < n_; ++i) b[i] = r[static_cast<std::size_t>(i) * S + s];
      const Eigen::VectorXd x = own_solve(s, b);
      const double scale = x.cwiseAbs().maxCoeff();
      for (int i = 0; i < n_; ++i)
        ASSERT_NEAR(z[static_cast<std::size_t>(i) * S + s], x[i], 1e-9 * scale) << "sigma point " << s << ", row " << i;
    }
  }
}

// The stand-in, then the first factor (another pattern: new blocks and buffers), then the
// factor again (the same pattern: its values only): each solve as a fresh solve's, bit for bit.
TEST_F(VulkanFactorSolveTest, AFactorAfterTheStandInSolvesAsAFreshOne) {
  const int S = 4;
  const std::vector<float> r = residuals(S);
  const std::vector<float> fresh = device_solve(r, S, -1, true, kFactorLoopTurns, false);
  SolveBuffers<float> buffers(r, S, -1, true);
  VulkanDevice& device = buffers.device;
  VulkanFactorSolve solve(device, n_, 0, S, buffers.cg(), kFactorLoopTurns);
  solve.upload_diagonal(A_);
  const std::size_t stand_in_bytes = solve.bytes();
  std::size_t factor_bytes = 0;
  for (int upload = 0; upload < 2; ++upload) {
    solve.upload(factor_);
    if (upload == 0) factor_bytes = solve.bytes();
    EXPECT_EQ(solve.bytes(), factor_bytes) << "the same pattern again: the same buffers";
    VkCommandBuffer cmd = device.begin();
    solve.record(cmd);
    device.submit_and_wait(cmd);
    const std::vector<float> z = buffers.z();
    EXPECT_EQ(0, std::memcmp(z.data(), fresh.data(), buffers.bytes)) << "upload " << upload;
  }
  EXPECT_GT(factor_bytes, stand_in_bytes) << "the factor's pattern got its own buffers";
}

// Until a factorisation succeeds: z = r / |diag A|, Jacobi's preconditioner, in one dispatch.
TEST_F(VulkanFactorSolveTest, TheDiagonalStandInIsJacobi) {
  const int S = 4;
  const std::vector<float> r = residuals(S);
  int dispatches = 0;
  const std::vector<float> z = device_solve(r, S, -1, true, kFactorLoopTurns, true, &dispatches);
  EXPECT_EQ(dispatches, 1);
  for (int i = 0; i < n_; ++i)
    for (int s = 0; s < S; ++s) {
      const std::size_t at = static_cast<std::size_t>(i) * S + s;
      ASSERT_NEAR(z[at], r[at] / std::abs(A_.coeff(i, i)), 1e-6 * std::abs(z[at]) + 1e-30) << "row " << i;
    }
}

// A bound on loop turns that a single block row of L exceeds is a DeviceError that says so,
// not a solve that llvmpipe would end silently.
TEST_F(VulkanFactorSolveTest, ABlockRowBeyondTheLoopBoundIsADeviceError) {
  try {
    device_solve(residuals(4), 4, -1, true, 8, false);
    FAIL() << "no error";
  } catch (const DeviceError& e) {
    EXPECT_NE(std::string(e.what()).find("loop turns"), std::string::npos) << e.what();
  }
}

// The ensemble on a CPU device: the factor by default (made at the first step), Jacobi when
// asked; the factor's steps take a fraction of Jacobi's iterations and end where Jacobi's do.
// With CG's iterations in three dispatches (node_product apart, what larger meshes run:
// cg_iteration_factor) the same bits as in two (cg_node_iteration_factor).
TEST_F(VulkanFactorSolveTest, TheEnsembleTakesItByDefaultOnACpuDevice) {
  if (list_vulkan_devices().front().type != "cpu") GTEST_SKIP() << "device 0 is not a CPU";
  const Scenario scenario = load_scenario(std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/liver.json");
  const Model model = make_model(scenario);
  const std::vector<int>& estimated = scenario.filter->estimate;
  const int S = static_cast<int>(estimated.size()) + 1;
  DeviceOptions jacobi_options;
  jacobi_options.preconditioner = Preconditioner::jacobi;
  DeviceOptions three_options;
  three_options.node_iteration_work = 0;
  VulkanEnsemble factorised(model, estimated, scenario.observations.nodes, S, DeviceOptions{});
  VulkanEnsemble three(model, estimated, scenario.observations.nodes, S, three_options);
  VulkanEnsemble jacobi(model, estimated, scenario.observations.nodes, S, jacobi_options);
  ASSERT_TRUE(factorised.factorised());
  ASSERT_TRUE(factorised.node_iteration());
  ASSERT_TRUE(three.factorised());
  ASSERT_FALSE(three.node_iteration());
  ASSERT_FALSE(jacobi.factorised());
  int factor_iterations = 0, jacobi_iterations = 0;
  for (int k = 1; k <= 6; ++k) {
    const Eigen::Vector3d so = scenario.control.trajectory.position(k * scenario.time.dt, scenario.control.start);
    const StepReport a = factorised.advance(so);
    const StepReport b = jacobi.advance(so);
    EXPECT_EQ(three.advance(so).cg_iterations, a.cg_iterations) << "step " << k;
    EXPECT_EQ(a.unconverged_count(), 0) << "step " << k;
    for (int s = 0; s < S; ++s) {
      factor_iterations += a.cg_iterations[static_cast<std::size_t>(s)];
      jacobi_iterations += b.cg_iterations[static_cast<std::size_t>(s)];
    }
  }
  EXPECT_GE(factorised.factorisations(), 1);
  EXPECT_LT(5 * factor_iterations, jacobi_iterations);
  for (int s = 0; s < S; ++s) {
    // Both stop at CG's float32 tolerance (|r| <= 1e-6 |b|, kSingleCgTolerance), from
    // different preconditioners: the velocities within 1e-3 of their size (1.4e-5 seen).
    EXPECT_TRUE(three.velocities(s) == factorised.velocities(s)) << "sigma point " << s;
    const Eigen::VectorXd v = factorised.velocities(s);
    EXPECT_GT(v.cwiseAbs().maxCoeff(), 0.0);
    EXPECT_LT((v - jacobi.velocities(s)).cwiseAbs().maxCoeff(), 1e-3 * v.cwiseAbs().maxCoeff())
        << "sigma point " << s;
  }
}

}  // namespace
}  // namespace sigmafem
