#include "host/data/csv_fields.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <system_error>

#include "host/common/input_error.h"
#include "host/common/input_file.h"

namespace sigmafem {

std::string trim(const std::string& s) {
  const size_t begin = s.find_first_not_of(" \t\r");
  if (begin == std::string::npos) return "";
  const size_t end = s.find_last_not_of(" \t\r");
  return s.substr(begin, end - begin + 1);
}

std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) fields.push_back(trim(field));
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

bool parse_double(const std::string& text, double& value) {
  if (text.empty()) return false;
  const char* first = text.data();
  const char* last = text.data() + text.size();
  const auto result = std::from_chars(first, last, value);
  return result.ec == std::errc() && result.ptr == last && std::isfinite(value);
}

std::vector<std::string> read_csv_file(
    const std::string& path, const std::string& where,
    const std::function<void(const std::vector<std::string>&, const std::string&, bool)>& on_line) {
  check_input_file(path, where, kMaxTableBytes);
  std::ifstream in(path);
  if (!in) throw InputError(where + ": cannot open the file (unreadable)");
  std::vector<std::string> comments;
  bool header_seen = false, row_seen = false;
  std::string raw;
  for (int line_number = 1; std::getline(in, raw); ++line_number) {
    const std::string line = trim(std::string(line_number == 1 ? without_byte_order_mark(raw) : raw));
    if (line.empty()) continue;
    if (line[0] == '#') {
      if (!header_seen) comments.push_back(trim(line.substr(1)));
      continue;
    }
    on_line(split_fields(line), where + " line " + std::to_string(line_number) + ": ", !header_seen);
    row_seen = header_seen;
    header_seen = true;
  }
  if (!header_seen) throw InputError(where + ": empty file; expected a header line");
  if (!row_seen) throw InputError(where + ": no data rows after the header");
  return comments;
}

}  // namespace sigmafem
