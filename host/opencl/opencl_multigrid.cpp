#include "host/opencl/opencl_multigrid.h"

#include "device_layout.h"
#include "host/ensemble/device_readout.h"

namespace sigmafem {

OpenClMultigrid::OpenClMultigrid(OpenClDevice& device, int sigma_count)
    : device_(device), S_(static_cast<cl_uint>(sigma_count)),
      k_smooth_(device.kernel("mg_smooth")), k_residual_(device.kernel("mg_residual")),
      k_product_(device.kernel("mg_product")) {
  for (cl::Kernel* kernel : {&k_smooth_, &k_residual_, &k_product_}) kernel->setArg(0, S_);
}

cl::Buffer OpenClMultigrid::reals(const std::vector<double>& values) {
  std::vector<unsigned char> bytes = to_device_reals(values, device_.precision());
  bytes_ += bytes.size();
  return cl::Buffer(device_.context(), CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, bytes.size(), bytes.data());
}

cl::Buffer OpenClMultigrid::vector_buffer(Eigen::Index rows) {
  const std::size_t bytes = static_cast<std::size_t>(rows) * S_ * device_.real_size();
  bytes_ += bytes;
  return cl::Buffer(device_.context(), CL_MEM_READ_WRITE, bytes);
}

OpenClMultigrid::Matrix OpenClMultigrid::matrix_buffers(const RowMajorMatrix& M) {
  Matrix matrix;
  matrix.rows = static_cast<cl_uint>(M.rows());
  const auto integers = [&](const int* data, std::size_t count) {
    bytes_ += count * sizeof(cl_int);
    return cl::Buffer(device_.context(), CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, count * sizeof(cl_int),
                      const_cast<int*>(data));
  };
  matrix.row_start = integers(M.outerIndexPtr(), static_cast<std::size_t>(M.rows()) + 1);
  matrix.columns = integers(M.innerIndexPtr(), static_cast<std::size_t>(M.nonZeros()));
  matrix.values = reals(std::vector<double>(M.valuePtr(), M.valuePtr() + M.nonZeros()));
  return matrix;
}

void OpenClMultigrid::upload(const NestedMultigrid& multigrid) {
  // Made anew at each refresh: the Galerkin products' patterns stay, but a refresh is rare
  // (the refresh rule) against the steps between.
  bytes_ = 0;
  levels_.assign(static_cast<std::size_t>(multigrid.level_count()), Level());
  for (int l = 0; l < multigrid.level_count(); ++l) {
    const NestedMultigrid::Level& from = multigrid.level(l);
    Level& level = levels_[static_cast<std::size_t>(l)];
    const bool inverted = l + 1 == multigrid.level_count() && multigrid.coarsest_inverse().size() > 0;
    if (inverted) {
      level.matrix = matrix_buffers(RowMajorMatrix(multigrid.coarsest_inverse().sparseView(0.0, 0.0)));
    } else {
      level.matrix = matrix_buffers(from.matrix);
      std::vector<double> steps;
      for (const NestedMultigrid::ChebyshevStep& step : from.smoothing) steps.insert(steps.end(), {step.previous, step.residual});
      level.steps = reals(steps);
      level.diagonal = reals(std::vector<double>(from.diagonal.data(), from.diagonal.data() + from.diagonal.size()));
      for (int i = 0; i < 2; ++i) {
        level.x[i] = vector_buffer(from.matrix.rows());
        level.p[i] = vector_buffer(from.matrix.rows());
      }
    }
    if (l + 1 < multigrid.level_count()) {
      level.prolongation = matrix_buffers(from.prolongation);
      level.restriction = matrix_buffers(from.restriction);
      level.r = vector_buffer(from.matrix.rows());
    }
    if (l > 0) {
      level.b = vector_buffer(from.matrix.rows());
      level.correction = vector_buffer(from.matrix.rows());
    }
  }
  launches_ = multigrid.launches();
  upload_shift(std::vector<double>(static_cast<std::size_t>(multigrid.level(0).matrix.rows()) * S_, 0.0));
}

void OpenClMultigrid::upload_shift(const std::vector<double>& shift) {
  if (!shift_()) {
    shift_ = reals(shift);
    return;
  }
  const std::vector<unsigned char> bytes = to_device_reals(shift, device_.precision());
  device_.queue().enqueueWriteBuffer(shift_, CL_TRUE, 0, bytes.size(), bytes.data());
}

void OpenClMultigrid::run(cl::Kernel& kernel, cl_uint rows) {
  kernel.setArg(1, rows);
  const std::size_t items = static_cast<std::size_t>(rows) * S_, group = SF_ITEMS_PER_GROUP;
  cl::Event event;
  device_.queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange((items + group - 1) / group * group),
                                       cl::NDRange(group), nullptr, &event);
  device_.record(kernel, event);
}

const cl::Buffer& OpenClMultigrid::vector(const MultigridVector& v, const cl::Buffer& r, const cl::Buffer& z) const {
  const Level& level = levels_[static_cast<std::size_t>(v.level)];
  using Role = MultigridVector::Role;
  switch (v.role) {
    case Role::rhs: return v.level == 0 ? r : level.b;
    case Role::result: return v.level == 0 ? z : level.correction;
    case Role::x0: return level.x[0];
    case Role::x1: return level.x[1];
    case Role::p0: return level.p[0];
    case Role::p1: return level.p[1];
    case Role::residual: break;
  }
  return level.r;
}

void OpenClMultigrid::enqueue(const cl::Buffer& r, const cl::Buffer& z) {
  using Kind = MultigridLaunch::Kind;
  for (const MultigridLaunch& launch : launches_) {
    const Level& level = levels_[static_cast<std::size_t>(launch.level)];
    const cl::Buffer& in = vector(launch.in, r, z);
    const cl::Buffer& out = vector(launch.out, r, z);
    const cl_uint shifted = launch.shifted ? 1 : 0;
    if (launch.kind == Kind::smooth) {
      k_smooth_.setArg(2, static_cast<cl_uint>(launch.step));
      k_smooth_.setArg(3, static_cast<cl_uint>(launch.from_zero ? 1 : 0));
      k_smooth_.setArg(4, shifted);
      k_smooth_.setArg(5, level.matrix.row_start);
      k_smooth_.setArg(6, level.matrix.columns);
      k_smooth_.setArg(7, level.matrix.values);
      k_smooth_.setArg(8, level.diagonal);
      k_smooth_.setArg(9, level.steps);
      k_smooth_.setArg(10, shift_);
      k_smooth_.setArg(11, in);
      k_smooth_.setArg(12, vector(launch.x, r, z));
      k_smooth_.setArg(13, vector(launch.p, r, z));
      k_smooth_.setArg(14, out);
      k_smooth_.setArg(15, vector(launch.p_out, r, z));
      run(k_smooth_, level.matrix.rows);
    } else if (launch.kind == Kind::residual) {
      k_residual_.setArg(2, shifted);
      k_residual_.setArg(3, level.matrix.row_start);
      k_residual_.setArg(4, level.matrix.columns);
      k_residual_.setArg(5, level.matrix.values);
      k_residual_.setArg(6, shift_);
      k_residual_.setArg(7, in);
      k_residual_.setArg(8, vector(launch.x, r, z));
      k_residual_.setArg(9, out);
      run(k_residual_, level.matrix.rows);
    } else {
      const Matrix& M = launch.kind == Kind::restriction    ? level.restriction
                        : launch.kind == Kind::prolongation ? level.prolongation
                                                            : level.matrix;
      k_product_.setArg(2, static_cast<cl_uint>(launch.kind == Kind::prolongation ? 1 : 0));
      k_product_.setArg(3, M.row_start);
      k_product_.setArg(4, M.columns);
      k_product_.setArg(5, M.values);
      k_product_.setArg(6, in);
      k_product_.setArg(7, out);
      run(k_product_, M.rows);
    }
  }
}

}  // namespace sigmafem
