// OpenClMultigrid: NestedMultigrid's V-cycle (host/reference/nested_multigrid.h) on an OpenCL
// device for all S sigma points at once, CG's preconditioner in OpenCL's GPU form, where the
// factor's triangular solves do not go (issue 18): z = M^-1 r, r and z the ensemble's CG
// vectors ([row S + s]). Each level's matrices go down in CSR after every
// NestedMultigrid::set_matrix; the kernels (kernels/opencl/multigrid.cl) then run the V-cycle's
// launches (NestedMultigrid::launches): at each level but the coarsest kSmoothingDegree
// Chebyshev steps, the residual, its restriction, the coarser level, the prolongation of its
// result and the steps again, 2 x 3 + 3 launches; one for the coarsest when it is inverted.
#pragma once

#include <vector>

#include "host/opencl/opencl_device.h"
#include "host/reference/nested_multigrid.h"

namespace sigmafem {

class OpenClMultigrid {
 public:
  // The kernels must be built already (OpenClDevice::build_program). Throws cl::Error.
  OpenClMultigrid(OpenClDevice& device, int sigma_count);
  ~OpenClMultigrid();   // waits for the shift's write still reading its host copy
  OpenClMultigrid(const OpenClMultigrid&) = delete;
  OpenClMultigrid& operator=(const OpenClMultigrid&) = delete;

  // The hierarchy's matrices, diagonals and smoothing steps (`multigrid` ready), written over
  // the last one's (DeviceError where a level's size differs from the first's). Throws
  // cl::Error.
  void upload(const NestedMultigrid& multigrid);
  // Each sigma point's shift at the finest level: rows x S reals, [row S + s].
  void upload_shift(const std::vector<double>& shift);
  // Enqueues z = M^-1 r for every sigma point (after upload()).
  void enqueue(const cl::Buffer& r, const cl::Buffer& z);
  // Bytes of device memory it holds.
  std::size_t device_bytes() const { return bytes_; }

 private:
  struct Matrix {
    cl::Buffer row_start, columns, values;
    cl_uint rows = 0;
    std::size_t nonzeros = 0;
  };
  struct Level {
    Matrix matrix, prolongation, restriction;   // matrix: NestedMultigrid::launch_matrix
    cl::Buffer diagonal, steps;
    // [row S + s]: the right-hand side and the result (coarser levels: the finest has CG's r
    // and z), the smoothing's iterates and steps (two each: a step reads one, writes the
    // other), the residual.
    cl::Buffer b, correction, x[2], p[2], r;
  };
  // The levels' buffers, made at the first upload (sizes from `multigrid`), the shift zero.
  void make_levels(const NestedMultigrid& multigrid);
  Matrix matrix_buffers(const RowMajorMatrix& M);
  cl::Buffer buffer(std::size_t bytes);
  cl::Buffer vector_buffer(Eigen::Index rows);
  void write(const cl::Buffer& to, const void* data, std::size_t bytes);
  void write_reals(const cl::Buffer& to, const std::vector<double>& values);
  // M's values into `to`, made for a matrix of its size (else a DeviceError).
  void write_matrix(const Matrix& to, const RowMajorMatrix& M);
  void run(cl::Kernel& kernel, cl_uint rows);

  OpenClDevice& device_;
  cl_uint S_;
  std::vector<Level> levels_;
  std::vector<MultigridLaunch> launches_;   // the V-cycle (NestedMultigrid::launches)
  cl::Buffer shift_;
  std::vector<unsigned char> shift_bytes_;   // the last write's copy, until shift_written_
  cl::Event shift_written_;
  std::size_t bytes_ = 0;
  cl::Kernel k_smooth_, k_residual_, k_product_;
};

}  // namespace sigmafem
