// The checked reading of a hand-written JSON file (a scenario): parsing that names a repeated
// key and the line of a syntax error, and field access that throws an InputError
// "scenario FILE: FIELD: what is wrong" with the field's path (`time.dt`,
// `ligaments[1].stiffness`) and, for a typo, the field it probably meant. The scenario's
// sections are read with it in scenario_load.cpp.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "host/common/input_error.h"
#include "host/common/physical_limits.h"

namespace sigmafem {
namespace checked_json {

using nlohmann::json;

// Text helpers for messages: "s", "a, b, c", what a JSON value is ("expected X, found Y"),
// " (did you mean "x"?)" when one candidate is within two edits (else ""), and field paths
// ("a.b", "a[3]").
std::string in_quotes(const std::string& s);
std::string join(const std::vector<std::string>& items);
std::string describe(const json& value);
std::string suggestion(const std::string& word, const std::vector<std::string>& candidates);
std::string child(const std::string& path, const std::string& key);
std::string element(const std::string& path, size_t index);

// Field access with checks. All of them throw with the field's path.

class Checker {
 public:
  explicit Checker(std::string file) : file_(std::move(file)) {}

  // The JSON of the file's `text`; a syntax error named by line and column, a repeated key by
  // its field path.
  json parse(const std::string& text) const;

  [[noreturn]] void fail(const std::string& path, const std::string& what) const {
    throw InputError("scenario " + file_ + ": " + path + ": " + what);
  }

  // A problem with the file as a whole, before any field can be named.
  [[noreturn]] void fail_file(const std::string& what) const {
    throw InputError("scenario " + file_ + ": " + what);
  }

  void require(bool ok, const std::string& path, const std::string& what) const {
    if (!ok) fail(path, what);
  }

  // `value` must be an object with only `allowed` keys and every `required` one. The root
  // object's path is "", and its unknown or missing fields are named alone ("meshh").
  void check_object(const json& value, const std::string& path,
                    const std::vector<std::string>& allowed,
                    const std::vector<std::string>& required) const {
    require(value.is_object(), path.empty() ? "(top level)" : path,
            "expected an object {...}, found " + describe(value));
    for (const auto& item : value.items()) {
      if (std::find(allowed.begin(), allowed.end(), item.key()) == allowed.end()) {
        fail(child(path, item.key()), "unknown field" + suggestion(item.key(), allowed) +
                                          "; allowed here: " + join(allowed));
      }
    }
    for (const std::string& key : required) {
      require(value.contains(key), child(path, key), "missing required field");
    }
  }

  double number(const json& value, const std::string& path) const {
    require(value.is_number(), path, "expected a number, found " + describe(value));
    const double x = value.get<double>();
    // A literal such as 1e999 parses to infinity; no scenario quantity may be infinite.
    require(std::isfinite(x), path, "expected a finite number, found " + value.dump());
    require(std::fabs(x) <= kMaxScenarioMagnitude, path,
            value.dump() + " is beyond +-" + message_number(kMaxScenarioMagnitude) +
                ", more than any quantity of a scenario in SI units (a unit slip?)");
    return x;
  }

  // Integers may be written 1500 or 1.5e3, but not 1500.5.
  int integer(const json& value, const std::string& path) const {
    const std::string found = "expected an integer, found " + describe(value);
    require(value.is_number(), path, found);
    const double x = value.is_number_unsigned()  ? static_cast<double>(value.get<std::uint64_t>())
                     : value.is_number_integer() ? static_cast<double>(value.get<std::int64_t>())
                                                 : value.get<double>();
    require(std::isfinite(x) && x == std::floor(x), path, found);
    require(x >= INT_MIN && x <= INT_MAX, path, "integer " + value.dump() + " is out of range");
    return static_cast<int>(x);
  }

  std::string string(const json& value, const std::string& path) const {
    require(value.is_string(), path, "expected a string \"...\", found " + describe(value));
    return value.get<std::string>();
  }

  Eigen::Vector3d vector3(const json& value, const std::string& path) const {
    require(value.is_array() && value.size() == 3, path,
            "expected an array of 3 numbers [x, y, z], found " + describe(value));
    Eigen::Vector3d v;
    for (size_t k = 0; k < 3; ++k)
      v[static_cast<Eigen::Index>(k)] = number(value[k], element(path, k));
    return v;
  }

  const json& array(const json& value, const std::string& path) const {
    require(value.is_array(), path, "expected an array [...], found " + describe(value));
    return value;
  }

  // Optional members of an already checked object: the fallback when absent.
  double number_or(const json& object, const std::string& path, const std::string& key,
                   double fallback) const {
    return object.contains(key) ? number(object.at(key), child(path, key)) : fallback;
  }
  int integer_or(const json& object, const std::string& path, const std::string& key,
                 int fallback) const {
    return object.contains(key) ? integer(object.at(key), child(path, key)) : fallback;
  }

  // Range checks: the message shows the rule and the value found.
  void positive(double x, const std::string& path) const {
    require(x > 0.0, path, "must be > 0, found " + message_number(x));
  }
  void non_negative(double x, const std::string& path) const {
    require(x >= 0.0, path, "must be >= 0, found " + message_number(x));
  }

 private:
  std::string file_;
};

}  // namespace checked_json
}  // namespace sigmafem
