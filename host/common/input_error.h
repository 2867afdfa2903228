// InputError: the one exception type for bad user input (files, scenario fields, meshes, data).
// Its message names where (file, line or field), what was expected and what was found, so
// the command line can print it as is and exit non-zero.
#pragma once

#include <stdexcept>
#include <string>

namespace sigmafem {

class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
};

}  // namespace sigmafem
