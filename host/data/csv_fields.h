// Field-level helpers for sigmafem's CSV files (trajectories, observations, truth): one way
// of splitting and reading numbers everywhere, independent of the C locale.
#pragma once

#include <string>
#include <vector>

namespace sigmafem {

// `s` without leading and trailing blanks (spaces, tabs, carriage returns).
std::string trim(const std::string& s);

// The comma-separated fields of a line, each trimmed; a trailing comma gives a last empty
// field, so that the count is honest.
std::vector<std::string> split_fields(const std::string& line);

// Reads a finite number that fills the whole text (std::from_chars: no locale, no "nan",
// no "inf"). Returns false for anything else, including an empty text.
bool parse_double(const std::string& text, double& value);

}  // namespace sigmafem
