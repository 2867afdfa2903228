// How sigmafem prints numbers in its CSV files: shortest round-trip-safe text is not needed,
// but the same number must always give the same bytes on every platform, so one printf
// format is used everywhere.
#pragma once

#include <cstdio>
#include <string>

namespace sigmafem {

// 10 significant digits: below 1e-9 m on positions of about a metre, far under any noise.
inline std::string format_number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", value);
  return buffer;
}

}  // namespace sigmafem
