// InputError: the one exception type for bad user input (files, scenario fields, meshes, data).
// Its message names where (file, line or field), what was expected and what was found, so
// the command line can print it as is and exit non-zero.
#pragma once

#include <Eigen/Core>
#include <sstream>
#include <stdexcept>
#include <string>

namespace sigmafem {

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

// A number as a message shows it: %g-like, 6 significant digits, enough to recognise the value
// the user wrote (the CSV files' own format is data/csv_format.h).
inline std::string message_number(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// A point or vector as a message shows it: [x, y, z], each as message_number.
inline std::string message_point(const Eigen::Vector3d& p) {
  return "[" + message_number(p.x()) + ", " + message_number(p.y()) + ", " + message_number(p.z()) + "]";
}

}  // namespace sigmafem
