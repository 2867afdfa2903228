#include "host/vulkan/vulkan_factor_solve.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "device_layout.h"
#include "host/vulkan/vulkan_push_constants.h"

namespace sigmafem {
namespace {

// A block-row or block-column step of factor_solve.comp turns once per block (per chunk of 8
// with the shared reads), its loop once more on leaving, and at most 6 more in the loops over
// a panel's 4 rows (if the compiler does not unroll them) and the step loop: counted, to be
// safe.
constexpr long long kStepTurns = 8;

// V's row length on the device: m rounded up to 4 (factor_solve.comp reads 4 at a time).
std::size_t padded(std::size_t m) { return (m + 3) / 4 * 4; }

}  // namespace

VulkanFactorSolve::VulkanFactorSolve(VulkanDevice& device, int rows, int spring_rows, int sigma_count,
                                     const CgBuffers& cg, long long loop_turns)
    : device_(device), rows_(rows), S_(sigma_count), spring_rows_(spring_rows), loop_turns_(loop_turns),
      cg_(cg) {
  const std::size_t n = static_cast<std::size_t>(rows), real = device_.real_size();
  const std::size_t m = static_cast<std::size_t>(spring_rows_);
  spring_at_ = make(4 * (2 + n));
  spring_solves_ = make(real * n * padded(m));
  spring_coupling_ = make(real * m * m * static_cast<std::size_t>(S_));
  split_ = split_lanes(device_.info(), S_);
  shared_ = shares_blocks(device_.info(), S_);
  group_ = static_cast<std::uint32_t>(shared_ ? kLanes : std::min(S_, kLanes) * split_);
  groups_ = (static_cast<std::uint32_t>(S_ * split_) + group_ - 1) / group_;
}

int VulkanFactorSolve::split_lanes(const VulkanDeviceInfo& info, int sigma_count) {
  if (!info.subgroup_shuffle || sigma_count <= 0) return 1;
  const int lanes = std::min<int>(kLanes, static_cast<int>(info.subgroup_size));
  int split = 1;
  while (2 * split * sigma_count <= lanes) split *= 2;
  return split;
}

bool VulkanFactorSolve::shares_blocks(const VulkanDeviceInfo& info, int sigma_count) {
  return info.shuffles_groups_of(kLanes) && split_lanes(info, sigma_count) == 1;
}

VulkanBuffer VulkanFactorSolve::make(std::size_t bytes) {
  bytes_ += bytes;
  return device_.buffer(bytes, "the factor");
}

void VulkanFactorSolve::upload_ints(const VulkanBuffer& buffer, const std::vector<int>& values) {
  if (!values.empty()) device_.upload(buffer, values.data(), values.size() * sizeof(int));
}

void VulkanFactorSolve::make_layout(const Eigen::SparseMatrix<double>& L, const int* order) {
  auto layout = std::make_unique<Layout>();
  layout->blocks = std::make_unique<FactorBlocks>(L, order);
  const FactorBlocks& b = *layout->blocks;
  const std::size_t P = static_cast<std::size_t>(b.panels()), B = std::max<std::size_t>(b.blocks(), 1);
  const std::size_t vec4 = 4 * device_.real_size();
  // y's 4 P slots, then V^T y and H V^T y, then r.z between dispatches (factor_solve.comp), S
  // times, a copy per lane of a sigma point.
  const std::size_t work_texels = P + 2 * padded(static_cast<std::size_t>(spring_rows_)) / 4 + 1;
  layout->forward_starts = make(4 * (P + 1));
  layout->forward_panel = make(4 * B);
  layout->backward_starts = make(4 * (P + 1));
  layout->backward_panel = make(4 * B);
  layout->slot_rows = make(4 * 4 * P);
  layout->triangles = make(vec4 * 4 * P);
  layout->forward_blocks = make(vec4 * 4 * B);
  layout->backward_blocks = make(vec4 * 4 * B);
  layout->work = make(vec4 * work_texels * static_cast<std::size_t>(S_ * split_));
  upload_ints(layout->forward_starts, b.forward_starts());
  upload_ints(layout->forward_panel, b.forward_panel());
  upload_ints(layout->backward_starts, b.backward_starts());
  upload_ints(layout->backward_panel, b.backward_panel());
  upload_ints(layout->slot_rows, b.slot_rows());
  const char* name = split_ > 1 ? "factor_solve_split" : shared_ ? "factor_solve_shared" : "factor_solve";
  const bool stores_z = cg_.z.buffer != VK_NULL_HANDLE;
  layout->kernel = device_.kernel(name, SF_FACTOR_SOLVE_BINDINGS,
                                  {group_, static_cast<std::uint32_t>(P), stores_z ? 1u : 0u});
  const Layout& l = *layout;
  // Without z, r stands at its binding (never written there).
  layout->set = device_.bind(l.kernel, {l.forward_starts, l.forward_panel, l.backward_starts, l.backward_panel,
                                        l.slot_rows, cg_.r, stores_z ? cg_.z : cg_.r, cg_.active, spring_at_,
                                        spring_solves_, spring_coupling_, l.triangles, l.forward_blocks,
                                        l.backward_blocks, l.work, l.work, cg_.d, cg_.rz});
  layout_ = std::move(layout);
}

void VulkanFactorSolve::upload_values() {
  const FactorBlocks& b = *layout_->blocks;
  device_.upload_reals(layout_->triangles, b.triangles());
  device_.upload_reals(layout_->forward_blocks, b.forward_values());
  device_.upload_reals(layout_->backward_blocks, b.backward_values());
}

void VulkanFactorSolve::upload(const FactorisedPreconditioner& factor) {
  const Eigen::SparseMatrix<double>& L = factor.lower();
  if (L.rows() != rows_)
    throw DeviceError("the factor has " + std::to_string(L.rows()) + " rows; the Vulkan solve was made for " +
                      std::to_string(rows_));
  send(L, factor.order());
  upload_spring_rows(0, {});   // the last correction was the last factor's
}

void VulkanFactorSolve::send(const Eigen::SparseMatrix<double>& L, const int* order) {
  if (layout_ && layout_->blocks->same_pattern(L))
    layout_->blocks->assign_values(L);
  else
    make_layout(L, order);
  upload_values();
}

bool VulkanFactorSolve::upload_springs(const SpringCorrection& springs) {
  if (!layout_) throw DeviceError("the factor's spring correction sent before the factor");
  if (springs.size() != spring_rows_ || !springs.prepared())
    throw DeviceError("the factor's spring correction has " + std::to_string(springs.size()) +
                      " rows (prepared: " + (springs.prepared() ? "yes" : "no") +
                      "); the Vulkan buffers hold " + std::to_string(spring_rows_));
  // A step of the correction sums over the reached rows or over m (factor_solve.comp).
  const long long longest = std::max<long long>(springs.size(), static_cast<long long>(springs.reached().size()));
  if (longest + 5 > loop_turns_) return false;
  const Eigen::MatrixXd& V = springs.reached_values();
  const std::size_t M = padded(static_cast<std::size_t>(V.cols()));
  std::vector<double> values(static_cast<std::size_t>(V.rows()) * M, 0.0);   // by rows, zeros after m
  for (Eigen::Index u = 0; u < V.rows(); ++u)
    for (Eigen::Index j = 0; j < V.cols(); ++j) values[static_cast<std::size_t>(u) * M + static_cast<std::size_t>(j)] = V(u, j);
  device_.upload_reals(spring_solves_, values);
  upload_spring_rows(springs.size(), springs.reached());
  return true;
}

void VulkanFactorSolve::record_couplings(VkCommandBuffer cmd, const std::vector<double>& couplings) const {
  const std::size_t m = static_cast<std::size_t>(spring_rows_);
  if (couplings.size() != m * m * static_cast<std::size_t>(S_))
    throw DeviceError("the springs' couplings: " + std::to_string(couplings.size()) + " reals for " +
                      std::to_string(m * m * static_cast<std::size_t>(S_)));
  device_.update_reals(cmd, spring_coupling_, couplings);
}

void VulkanFactorSolve::upload_spring_rows(int m, const std::vector<int>& reached) {
  std::vector<int> at = {m, static_cast<int>(reached.size())};
  for (const int row : reached) at.push_back(layout_->blocks->slot(row));   // L's rows -> y's slots
  upload_ints(spring_at_, at);
  spring_steps_ = {m, static_cast<int>(reached.size())};
  plan_dispatches();
}

void VulkanFactorSolve::upload_diagonal(const Eigen::SparseMatrix<double>& A) {
  const std::vector<double> values = diagonal_stand_in(A);
  const Eigen::Index n = static_cast<Eigen::Index>(values.size());
  Eigen::SparseMatrix<double> L(n, n);
  L.reserve(Eigen::VectorXi::Ones(n));
  for (Eigen::Index i = 0; i < n; ++i) L.insert(i, i) = values[static_cast<std::size_t>(i)];
  L.makeCompressed();
  std::vector<int> identity(static_cast<std::size_t>(n));
  for (Eigen::Index i = 0; i < n; ++i) identity[static_cast<std::size_t>(i)] = static_cast<int>(i);
  send(L, identity.data());
  upload_spring_rows(0, {});
}

void VulkanFactorSolve::plan_dispatches() {
  // The steps of factor_solve.comp (the forward block rows, the correction's 2m + u, the
  // backward block columns from the last, CG's d) cut into ranges of at most loop_turns_ turns.
  ranges_.clear();
  const FactorBlocks& b = *layout_->blocks;
  const auto [m, reached] = spring_steps_;
  // A block row or column turns once a block, or with the shared reads once a chunk of 8.
  const int chunk = shared_ ? 8 : 1;
  auto block_turns = [chunk](int blocks) { return static_cast<long long>((blocks + chunk - 1) / chunk) + kStepTurns; };
  std::vector<long long> turns;
  for (int q = 0; q < b.panels(); ++q) turns.push_back(block_turns(b.forward_starts()[q + 1] - b.forward_starts()[q]));
  const long long quads = static_cast<long long>(padded(static_cast<std::size_t>(m)) / 4);
  turns.insert(turns.end(), static_cast<std::size_t>(quads), reached + 2);   // (V^T y)_4i..4i+3
  turns.insert(turns.end(), static_cast<std::size_t>(m), m + 5);             // (H V^T y)_j, the padding
  turns.insert(turns.end(), static_cast<std::size_t>(reached), quads + 2);   // y -= V H V^T y, a slot
  for (int p = b.panels() - 1; p >= 0; --p)
    turns.push_back(block_turns(b.backward_starts()[p + 1] - b.backward_starts()[p]));
  // CG's d after them, SF_FACTOR_FINISH_QUADS of y's quads a step (a lane's share).
  const int finish_quads = static_cast<int>(SF_FACTOR_FINISH_QUADS);
  turns.insert(turns.end(), static_cast<std::size_t>((b.panels() + finish_quads - 1) / finish_quads),
               (finish_quads + split_ - 1) / split_ + kStepTurns);
  long long sum = 0;
  std::uint32_t first = 0;
  for (std::size_t step = 0; step < turns.size(); ++step) {
    if (turns[step] > loop_turns_)
      throw DeviceError("the factor's step " + std::to_string(step) + " turns " + std::to_string(turns[step]) +
                        " times, more than a Vulkan dispatch may turn (" + std::to_string(loop_turns_) +
                        " loop turns)");
    if (sum + turns[step] > loop_turns_) {
      ranges_.emplace_back(first, static_cast<std::uint32_t>(step));
      first = static_cast<std::uint32_t>(step);
      sum = 0;
    }
    sum += turns[step];
  }
  ranges_.emplace_back(first, static_cast<std::uint32_t>(turns.size()));
}

void VulkanFactorSolve::record(VkCommandBuffer cmd, std::uint32_t finish) const {
  if (finish == SF_FACTOR_FINISH_NONE && cg_.z.buffer == VK_NULL_HANDLE)
    throw std::logic_error("VulkanFactorSolve::record: z alone asked of a solve made without z");
  VulkanPushConstants push;   // S, the first step, one past the last, the finish (factor_solve.comp)
  push.S = static_cast<std::uint32_t>(S_);
  push.max_iterations = static_cast<std::int32_t>(finish);
  for (const auto& [first, last] : ranges_) {
    push.count = first;
    push.p = last;
    device_.dispatch(cmd, layout_->kernel, layout_->set, &push, groups_);
    device_.barrier(cmd);
  }
}

}  // namespace sigmafem
