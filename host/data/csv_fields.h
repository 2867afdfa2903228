// Field-level helpers for sigmafem's CSV files (trajectories, observations, truth): one way
// of splitting and reading numbers everywhere, independent of the C locale.
#pragma once

#include <functional>
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

// Reads a sigmafem CSV file: blank lines are skipped, "#" lines before the header are
// returned as comments (without the "#"), later ones ignored; the first other line is the
// header and each line after it a row. `on_line(fields, at, is_header)` sees them in order,
// `at` being "<where> line N: " for messages. Throws InputError ("<where>: ...") if the file
// cannot be opened, and if it has no header or no row.
std::vector<std::string> read_csv_file(
    const std::string& path, const std::string& where,
    const std::function<void(const std::vector<std::string>& fields, const std::string& at,
                             bool is_header)>& on_line);

}  // namespace sigmafem
