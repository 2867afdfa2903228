#include "host/opencl/opencl_multigrid.h"

#include <algorithm>

#include "device_layout.h"
#include "host/ensemble/device_readout.h"

namespace sigmafem {

OpenClMultigrid::OpenClMultigrid(OpenClDevice& device, int sigma_count)
    : device_(device), S_(static_cast<cl_uint>(sigma_count)),
      k_smooth_(device.kernel("mg_smooth")), k_residual_(device.kernel("mg_residual")),
      k_product_(device.kernel("mg_product")) {
  for (cl::Kernel* kernel : {&k_smooth_, &k_residual_, &k_product_}) kernel->setArg(0, S_);
}

OpenClMultigrid::~OpenClMultigrid() {
  try {
    if (shift_written_()) shift_written_.wait();
  } catch (const cl::Error&) {   // nothing to report to from a destructor
  }
}

cl::Buffer OpenClMultigrid::buffer(std::size_t bytes) {
  bytes = std::max<std::size_t>(bytes, 1);
  bytes_ += bytes;
  return cl::Buffer(device_.context(), CL_MEM_READ_WRITE, bytes);
}

cl::Buffer OpenClMultigrid::vector_buffer(Eigen::Index rows) {
  return buffer(static_cast<std::size_t>(rows) * S_ * device_.real_size());
}

OpenClMultigrid::Matrix OpenClMultigrid::matrix_buffers(const RowMajorMatrix& M) {
  Matrix matrix;
  matrix.rows = static_cast<cl_uint>(M.rows());
  matrix.nonzeros = static_cast<std::size_t>(M.nonZeros());
  matrix.row_start = buffer((static_cast<std::size_t>(M.rows()) + 1) * sizeof(cl_int));
  matrix.columns = buffer(matrix.nonzeros * sizeof(cl_int));
  matrix.values = buffer(matrix.nonzeros * device_.real_size());
  return matrix;
}

void OpenClMultigrid::write(const cl::Buffer& to, const void* data, std::size_t bytes) {
  // Blocking: an upload is rare (the refresh rule), and the host arrays are temporaries.
  if (bytes > 0) device_.queue().enqueueWriteBuffer(to, CL_TRUE, 0, bytes, data);
}

void OpenClMultigrid::write_reals(const cl::Buffer& to, const std::vector<double>& values) {
  const std::vector<unsigned char> bytes = to_device_reals(values, device_.precision());
  write(to, bytes.data(), bytes.size());
}

void OpenClMultigrid::write_matrix(const Matrix& to, const RowMajorMatrix& M) {
  check_level_size(M, to.rows, to.nonzeros);
  write(to.row_start, M.outerIndexPtr(), (static_cast<std::size_t>(M.rows()) + 1) * sizeof(cl_int));
  write(to.columns, M.innerIndexPtr(), to.nonzeros * sizeof(cl_int));
  write_reals(to.values, std::vector<double>(M.valuePtr(), M.valuePtr() + M.nonZeros()));
}

void OpenClMultigrid::make_levels(const NestedMultigrid& multigrid) {
  levels_.assign(static_cast<std::size_t>(multigrid.level_count()), Level());
  for (int l = 0; l < multigrid.level_count(); ++l) {
    const NestedMultigrid::Level& from = multigrid.level(l);
    Level& level = levels_[static_cast<std::size_t>(l)];
    level.matrix = matrix_buffers(multigrid.launch_matrix(l));
    if (!from.smoothing.empty()) {
      level.steps = buffer(2 * from.smoothing.size() * device_.real_size());
      level.diagonal = buffer(static_cast<std::size_t>(from.diagonal.size()) * device_.real_size());
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
  shift_ = vector_buffer(multigrid.level(0).matrix.rows());
  write_reals(shift_, std::vector<double>(static_cast<std::size_t>(multigrid.level(0).matrix.rows()) * S_, 0.0));
  launches_ = multigrid.launches();
}

void OpenClMultigrid::upload(const NestedMultigrid& multigrid) {
  // The buffers are made at the first upload: later hierarchies of the same meshes have the
  // same sizes (the Galerkin products' patterns stay), and their values are written over.
  if (levels_.empty()) make_levels(multigrid);
  write_levels(
      multigrid, levels_, [&](const Matrix& to, const RowMajorMatrix& M) { write_matrix(to, M); },
      [&](const cl::Buffer& to, const std::vector<double>& values) { write_reals(to, values); });
}

void OpenClMultigrid::upload_shift(const std::vector<double>& shift) {
  // Not waited for (a host wait each filter step otherwise): the copy is kept until its write
  // is done, as OpenClEnsemble's writes.
  if (shift_written_()) shift_written_.wait();
  shift_bytes_ = to_device_reals(shift, device_.precision());
  device_.queue().enqueueWriteBuffer(shift_, CL_FALSE, 0, shift_bytes_.size(), shift_bytes_.data(), nullptr,
                                     &shift_written_);
}

void OpenClMultigrid::run(cl::Kernel& kernel, cl_uint rows) {
  kernel.setArg(1, rows);
  const std::size_t items = static_cast<std::size_t>(rows) * S_, group = SF_ITEMS_PER_GROUP;
  cl::Event event;
  device_.queue().enqueueNDRangeKernel(kernel, cl::NullRange, cl::NDRange((items + group - 1) / group * group),
                                       cl::NDRange(group), nullptr, &event);
  device_.record(kernel, event);
}

void OpenClMultigrid::enqueue(const cl::Buffer& r, const cl::Buffer& z) {
  using Kind = MultigridLaunch::Kind;
  for (const MultigridLaunch& launch : launches_) {
    const Level& level = levels_[static_cast<std::size_t>(launch.level)];
    const auto vector = [&](const MultigridVector& v) -> const cl::Buffer& { return multigrid_buffer(levels_, v, r, z); };
    const cl::Buffer& in = vector(launch.in);
    const cl::Buffer& out = vector(launch.out);
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
      k_smooth_.setArg(12, vector(launch.x));
      k_smooth_.setArg(13, vector(launch.p));
      k_smooth_.setArg(14, out);
      k_smooth_.setArg(15, vector(launch.p_out));
      run(k_smooth_, level.matrix.rows);
    } else if (launch.kind == Kind::residual) {
      k_residual_.setArg(2, shifted);
      k_residual_.setArg(3, level.matrix.row_start);
      k_residual_.setArg(4, level.matrix.columns);
      k_residual_.setArg(5, level.matrix.values);
      k_residual_.setArg(6, shift_);
      k_residual_.setArg(7, in);
      k_residual_.setArg(8, vector(launch.x));
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
