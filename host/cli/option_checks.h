// Checks of command-line numbers. CLI11's own (NonNegativeNumber, PositiveNumber, Range)
// compare the value with a bound, and every comparison with NaN is false, so "nan" passed
// them all; an unsigned option given "-1" wraps to 2^64-1. These refuse both, naming the value.
#pragma once

#include <CLI/CLI.hpp>
#include <cmath>
#include <string>

namespace sigmafem::cli {

// A finite number in [low, high] (or (low, high] when low_open).
inline CLI::Validator finite_between(double low, double high, bool low_open = false) {
  const std::string rule = std::string(low_open ? "(" : "[") + CLI::detail::to_string(low) + ", " +
                           CLI::detail::to_string(high) + "]";
  return CLI::Validator(
      [=](std::string& text) -> std::string {
        double value = 0.0;
        if (!CLI::detail::lexical_cast(text, value) || !std::isfinite(value) ||
            (low_open ? value <= low : value < low) || value > high)
          return "must be a finite number in " + rule + ", found " + text;
        return "";
      },
      "FLOAT in " + rule);
}

// A whole number >= 0 written with digits only (no sign, no exponent).
inline CLI::Validator whole_number() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos)
          return "must be a whole number >= 0, found " + text;
        return "";
      },
      "UINT");
}

}  // namespace sigmafem::cli
