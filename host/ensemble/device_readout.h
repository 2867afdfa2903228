// What the device ensembles (OpenCL, Vulkan) do alike on the host side of a transfer: device
// reals (float32 or float64, as the precision) to and from doubles, the sigma-innermost
// layout of a per-dof array (values[row * S + s], kernels/opencl/ensemble_layout.h) to and
// from an Eigen matrix, and the solver report assembled from the CG's per-sigma scalars.
// The transfers themselves are each back end's.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "filter/ensemble.h"
#include "host/common/device_options.h"

namespace sigmafem {

// Bytes of the device reals for `values` (converted to float in single precision).
std::vector<unsigned char> to_device_reals(const std::vector<double>& values, Precision precision);
// `count` device reals at `data`, as doubles.
std::vector<double> from_device_reals(const void* data, std::size_t count, Precision precision);

// d (rows x S) as values[row * S + s], and back.
std::vector<double> to_sigma_rows(const Eigen::MatrixXd& d);
Eigen::MatrixXd from_sigma_rows(const std::vector<double>& values, std::size_t rows, int S);
// Column s of values[row * S + s]; std::out_of_range naming `who` when there is no s.
std::vector<double> sigma_column(const std::vector<double>& values, std::size_t rows, int S, int s,
                                 const std::string& who);

// The step's solver report from the CG's per-sigma products, flags and r.r, b.b.
StepReport solver_report(const std::vector<std::int32_t>& iterations,
                         const std::vector<std::uint32_t>& converged, const std::vector<double>& rr,
                         const std::vector<double>& bb);

// "opencl single on DEVICE": the back end, its precision and its device.
std::string device_ensemble_description(const std::string& backend, Precision precision,
                                        const std::string& device);

}  // namespace sigmafem
