#include "host/ensemble/device_readout.h"

#include <cmath>
#include <cstring>
#include <stdexcept>

namespace sigmafem {

std::vector<unsigned char> to_device_reals(const std::vector<double>& values, Precision precision) {
  std::vector<unsigned char> bytes(values.size() * real_size(precision));
  if (bytes.empty()) return bytes;
  if (precision == Precision::single) {
    const std::vector<float> converted(values.begin(), values.end());
    std::memcpy(bytes.data(), converted.data(), bytes.size());
  } else {
    std::memcpy(bytes.data(), values.data(), bytes.size());
  }
  return bytes;
}

std::vector<double> from_device_reals(const void* data, std::size_t count, Precision precision) {
  if (count == 0) return {};
  if (precision == Precision::single) {
    std::vector<float> values(count);
    std::memcpy(values.data(), data, count * sizeof(float));
    return std::vector<double>(values.begin(), values.end());
  }
  std::vector<double> values(count);
  std::memcpy(values.data(), data, count * sizeof(double));
  return values;
}

std::vector<double> to_sigma_rows(const Eigen::MatrixXd& d) {
  const std::size_t rows = static_cast<std::size_t>(d.rows());
  const std::size_t S = static_cast<std::size_t>(d.cols());
  std::vector<double> values(rows * S);
  for (std::size_t row = 0; row < rows; ++row)
    for (std::size_t s = 0; s < S; ++s)
      values[row * S + s] = d(static_cast<Eigen::Index>(row), static_cast<Eigen::Index>(s));
  return values;
}

Eigen::MatrixXd from_sigma_rows(const std::vector<double>& values, std::size_t rows, int S) {
  Eigen::MatrixXd y(static_cast<Eigen::Index>(rows), S);
  for (std::size_t row = 0; row < rows; ++row)
    for (int s = 0; s < S; ++s) y(static_cast<Eigen::Index>(row), s) = values[row * S + s];
  return y;
}

std::vector<double> sigma_column(const std::vector<double>& values, std::size_t rows, int S, int s,
                                 const std::string& who) {
  if (s < 0 || s >= S) throw std::out_of_range(who + ": no sigma point " + std::to_string(s));
  std::vector<double> column(rows);
  for (std::size_t row = 0; row < rows; ++row) column[row] = values[row * S + s];
  return column;
}

StepReport solver_report(const std::vector<std::int32_t>& iterations,
                         const std::vector<std::uint32_t>& converged, const std::vector<double>& rr,
                         const std::vector<double>& bb) {
  StepReport report;
  report.cg_iterations.assign(iterations.begin(), iterations.end());
  report.converged.assign(converged.begin(), converged.end());
  report.relative_residual.resize(rr.size());
  for (std::size_t s = 0; s < rr.size(); ++s)
    report.relative_residual[s] = bb[s] > 0.0 ? std::sqrt(rr[s] / bb[s]) : 0.0;
  return report;
}

std::string device_ensemble_description(const std::string& backend, Precision precision,
                                        const std::string& device) {
  return backend + (precision == Precision::single ? " single" : " double") + " on " + device;
}

}  // namespace sigmafem
