#include "host/data/truth_table.h"

#include <algorithm>
#include <filesystem>
#include <sstream>

#include "host/common/input_error.h"
#include "host/data/csv_fields.h"
#include "host/data/csv_format.h"

namespace sigmafem {

int TruthTable::column(const std::string& name) const {
  for (std::size_t k = 0; k < names.size(); ++k)
    if (names[k] == name) return static_cast<int>(k);
  return -1;
}

std::string format_truth_csv(const TruthTable& table) {
  std::ostringstream out;
  for (const std::string& comment : table.comments) out << "# " << comment << '\n';
  out << "step,time";
  for (const std::string& name : table.names) out << ',' << name;
  out << '\n';
  for (std::size_t k = 0; k < table.steps.size(); ++k) {
    out << table.steps[k] << ',' << format_number(table.times[k]);
    for (Eigen::Index c = 0; c < table.stiffness.cols(); ++c)
      out << ',' << format_number(table.stiffness(static_cast<Eigen::Index>(k), c));
    out << '\n';
  }
  return out.str();
}

TruthTable read_truth_csv(const std::string& path) {
  TruthTable table;
  std::vector<std::vector<double>> rows;
  auto on_line = [&](const std::vector<std::string>& fields, const std::string& at, bool is_header) {
    if (is_header) {
      if (fields.size() < 3 || fields[0] != "step" || fields[1] != "time")
        throw InputError(at + "expected the header step,time,<ligament names...>");
      table.names.assign(fields.begin() + 2, fields.end());
      return;
    }
    if (fields.size() != table.names.size() + 2)
      throw InputError(at + "expected " + std::to_string(table.names.size() + 2) +
                       " fields, found " + std::to_string(fields.size()));
    std::vector<double> values(fields.size());
    for (std::size_t k = 0; k < fields.size(); ++k)
      if (!parse_double(fields[k], values[k]))
        throw InputError(at + "column " + (k == 0 ? std::string("step") : k == 1 ? "time" : table.names[k - 2]) +
                         " is not a finite number: \"" + fields[k] + "\"");
    if (values[0] != static_cast<double>(rows.size()))
      throw InputError(at + "step " + fields[0] + " is out of order: expected " +
                       std::to_string(rows.size()));
    table.steps.push_back(static_cast<int>(rows.size()));
    table.times.push_back(values[1]);
    rows.emplace_back(values.begin() + 2, values.end());
  };
  table.comments = read_csv_file(path, "truth " + path, on_line);
  table.stiffness.resize(static_cast<Eigen::Index>(rows.size()),
                         static_cast<Eigen::Index>(table.names.size()));
  for (std::size_t k = 0; k < rows.size(); ++k)
    for (std::size_t c = 0; c < table.names.size(); ++c)
      table.stiffness(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(c)) = rows[k][c];
  return table;
}

std::optional<TruthTable> read_optional_truth_csv(const std::string& path,
                                                  const std::vector<std::string>& ligament_names,
                                                  int row_count, std::ostream& warnings) {
  std::error_code error;
  if (!std::filesystem::exists(path, error)) return std::nullopt;
  const std::string ignored = "; it is optional, so the run goes on without the truth figures\n";
  try {
    TruthTable table = read_truth_csv(path);
    std::vector<std::string> sorted_names = table.names, expected = ligament_names;
    std::sort(sorted_names.begin(), sorted_names.end());
    std::sort(expected.begin(), expected.end());
    if (sorted_names != expected) {
      std::string listed;
      for (const std::string& name : ligament_names) listed += (listed.empty() ? "" : ",") + name;
      warnings << "warning: truth " << path << ": the ligament columns are not the scenario's (" << listed << ")"
               << ignored;
      return std::nullopt;
    }
    if (static_cast<int>(table.steps.size()) != row_count) {
      warnings << "warning: truth " << path << ": " << table.steps.size() << " rows, the observations have "
               << row_count << ignored;
      return std::nullopt;
    }
    return table;
  } catch (const InputError& e) {
    warnings << "warning: " << e.what() << ignored;
    return std::nullopt;
  }
}

}  // namespace sigmafem
