#include "host/vulkan/vulkan_multigrid.h"

#include <string>

#include "device_layout.h"

namespace sigmafem {

VulkanMultigrid::VulkanMultigrid(VulkanDevice& device, int sigma_count, const VulkanBuffer& r,
                                 const VulkanBuffer& z)
    : device_(device), S_(sigma_count), r_(r), z_(z),
      k_smooth_(device.kernel("mg_smooth", SF_MG_BINDINGS)),
      k_residual_(device.kernel("mg_residual", SF_MG_BINDINGS)),
      k_product_(device.kernel("mg_product", SF_MG_BINDINGS)) {
  none_ = make(8);
}

VulkanBuffer VulkanMultigrid::make(std::size_t bytes) {
  bytes_ += bytes;
  return device_.buffer(bytes, "the multigrid levels");
}

VulkanMultigrid::Matrix VulkanMultigrid::make_matrix(const RowMajorMatrix& M) {
  Matrix matrix;
  matrix.rows = static_cast<std::uint32_t>(M.rows());
  matrix.nonzeros = static_cast<std::size_t>(M.nonZeros());
  matrix.row_start = make(4 * (static_cast<std::size_t>(M.rows()) + 1));
  matrix.columns = make(4 * std::max<std::size_t>(1, matrix.nonzeros));
  matrix.values = make(device_.real_size() * std::max<std::size_t>(1, matrix.nonzeros));
  return matrix;
}

void VulkanMultigrid::upload_matrix(const Matrix& to, const RowMajorMatrix& M) {
  check_level_size(M, to.rows, to.nonzeros);
  device_.upload(to.row_start, M.outerIndexPtr(), 4 * (static_cast<std::size_t>(M.rows()) + 1));
  device_.upload(to.columns, M.innerIndexPtr(), 4 * to.nonzeros);
  device_.upload_reals(to.values, std::vector<double>(M.valuePtr(), M.valuePtr() + M.nonZeros()));
}

void VulkanMultigrid::make_levels(const NestedMultigrid& multigrid) {
  const std::size_t real = device_.real_size(), S = static_cast<std::size_t>(S_);
  const auto vector = [&](Eigen::Index rows) { return make(real * static_cast<std::size_t>(rows) * S); };
  levels_.assign(static_cast<std::size_t>(multigrid.level_count()), Level());
  for (int l = 0; l < multigrid.level_count(); ++l) {
    const NestedMultigrid::Level& from = multigrid.level(l);
    Level& level = levels_[static_cast<std::size_t>(l)];
    const Eigen::Index rows = from.matrix.rows();
    level.matrix = make_matrix(multigrid.launch_matrix(l));
    if (!from.smoothing.empty()) {
      level.diagonal = make(real * static_cast<std::size_t>(rows));
      level.steps = make(real * 2 * from.smoothing.size());
      for (int i = 0; i < 2; ++i) {
        level.x[i] = vector(rows);
        level.p[i] = vector(rows);
      }
    }
    if (l + 1 < multigrid.level_count()) {
      level.prolongation = make_matrix(from.prolongation);
      level.restriction = make_matrix(from.restriction);
      level.r = vector(rows);
    }
    if (l > 0) {
      level.b = vector(rows);
      level.correction = vector(rows);
    }
  }
  shift_ = vector(multigrid.level(0).matrix.rows());
  device_.upload(shift_, std::vector<unsigned char>(real * static_cast<std::size_t>(multigrid.level(0).matrix.rows()) * S, 0).data(),
                 real * static_cast<std::size_t>(multigrid.level(0).matrix.rows()) * S);
  plan(multigrid.launches());
}

void VulkanMultigrid::upload(const NestedMultigrid& multigrid) {
  if (levels_.empty()) make_levels(multigrid);
  write_levels(
      multigrid, levels_, [&](const Matrix& to, const RowMajorMatrix& M) { upload_matrix(to, M); },
      [&](const VulkanBuffer& to, const std::vector<double>& values) { device_.upload_reals(to, values); });
}

void VulkanMultigrid::add(const VulkanKernel& kernel, const Matrix& matrix, std::vector<VulkanBuffer> bound,
                          std::uint32_t step, std::uint32_t flags) {
  bound[SF_MG_ROW_START] = matrix.row_start;
  bound[SF_MG_COLUMNS] = matrix.columns;
  bound[SF_MG_VALUES] = matrix.values;
  Dispatch dispatch{&kernel, device_.bind(kernel, bound), VulkanPushConstants(), 0};
  dispatch.push.S = static_cast<std::uint32_t>(S_);
  dispatch.push.count = matrix.rows;
  dispatch.push.max_iterations = static_cast<std::int32_t>(step);
  dispatch.push.p = flags;
  const std::size_t items = static_cast<std::size_t>(matrix.rows) * static_cast<std::size_t>(S_);
  dispatch.groups = static_cast<std::uint32_t>((items + SF_ITEMS_PER_GROUP - 1) / SF_ITEMS_PER_GROUP);
  dispatches_.push_back(dispatch);
}

void VulkanMultigrid::plan(const std::vector<MultigridLaunch>& launches) {
  using Kind = MultigridLaunch::Kind;
  dispatches_.clear();
  const auto vector = [&](const MultigridVector& v) -> const VulkanBuffer& { return multigrid_buffer(levels_, v, r_, z_); };
  for (const MultigridLaunch& launch : launches) {
    const Level& level = levels_[static_cast<std::size_t>(launch.level)];
    std::vector<VulkanBuffer> bound(SF_MG_BINDINGS, none_);
    bound[SF_MG_IN] = vector(launch.in);
    bound[SF_MG_OUT] = vector(launch.out);
    const std::uint32_t shifted = launch.shifted ? SF_MG_SHIFTED : 0u;
    if (launch.shifted) bound[SF_MG_SHIFT] = shift_;
    if (launch.kind == Kind::smooth) {
      bound[SF_MG_DIAGONAL] = level.diagonal;
      bound[SF_MG_STEPS] = level.steps;
      bound[SF_MG_X] = vector(launch.x);
      bound[SF_MG_P] = vector(launch.p);
      bound[SF_MG_P_OUT] = vector(launch.p_out);
      add(k_smooth_, level.matrix, bound, static_cast<std::uint32_t>(launch.step),
          (launch.from_zero ? SF_MG_FROM_ZERO : 0u) | shifted);
    } else if (launch.kind == Kind::residual) {
      bound[SF_MG_X] = vector(launch.x);
      add(k_residual_, level.matrix, bound, 0, shifted);
    } else {
      const Matrix& M = launch.kind == Kind::restriction    ? level.restriction
                        : launch.kind == Kind::prolongation ? level.prolongation
                                                            : level.matrix;
      add(k_product_, M, bound, 0, launch.kind == Kind::prolongation ? SF_MG_ACCUMULATE : 0u);
    }
  }
}

void VulkanMultigrid::record_shift(VkCommandBuffer cmd, const std::vector<double>& shift) const {
  device_.update_reals(cmd, shift_, shift);
}

void VulkanMultigrid::record(VkCommandBuffer cmd) const {
  for (const Dispatch& dispatch : dispatches_) {
    device_.dispatch(cmd, *dispatch.kernel, dispatch.set, &dispatch.push, dispatch.groups);
    device_.barrier(cmd);
  }
}

}  // namespace sigmafem
