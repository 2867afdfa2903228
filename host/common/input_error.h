// InputError: the one exception type for bad user input (files, scenario fields, meshes, data).
// Its message names where (file, line or field), what was expected and what was found, so
// the command line can print it as is and exit non-zero.
#pragma once

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

}  // namespace sigmafem
