#include "host/scenario/checked_json.h"

#include <set>

namespace sigmafem {
namespace checked_json {
namespace {

// Levenshtein distance, to suggest the field or ligament a typo meant.
size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// nlohmann keeps the last of two equal keys without a word; in a hand-written scenario a
// repeated key is a mistake (an edit made in one place and not the other), so the parser
// callback tracks where it is and reports the repeated key by its field path.
class DuplicateKeyCheck {
 public:
  // Returns the path of a key that repeats, or "" if the event is fine.
  std::string on_event(json::parse_event_t event, const json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
        frames_.push_back({true, {}, {}, 0});
        break;
      case json::parse_event_t::array_start:
        frames_.push_back({false, {}, {}, 0});
        break;
      case json::parse_event_t::key: {
        Frame& top = frames_.back();
        top.key = parsed.get<std::string>();
        if (!top.keys.insert(top.key).second) return path();
        break;
      }
      case json::parse_event_t::value:
        next_element();
        break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        frames_.pop_back();
        next_element();
        break;
    }
    return "";
  }

 private:
  struct Frame {
    bool is_object;
    std::set<std::string> keys;  // objects: keys seen so far
    std::string key;             // objects: the key being read
    size_t index;                // arrays: index of the element being read
  };

  void next_element() {
    if (!frames_.empty() && !frames_.back().is_object) ++frames_.back().index;
  }

  std::string path() const {
    std::string out;
    for (const Frame& frame : frames_) {
      out = frame.is_object ? child(out, frame.key) : element(out, frame.index);
    }
    return out;
  }

  std::vector<Frame> frames_;
};

// nlohmann reports a byte offset (1-based, the last character it read); people count lines.
std::string line_and_column(const std::string& text, size_t byte) {
  const size_t end = std::min(byte > 0 ? byte - 1 : 0, text.size());
  size_t line = 1;
  size_t line_start = 0;
  for (size_t i = 0; i < end; ++i) {
    if (text[i] == '\n') {
      ++line;
      line_start = i + 1;
    }
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(end - line_start + 1);
}

// nlohmann's what() is "[json.exception.parse_error.101] parse error at line 3, column 5:
// syntax error while parsing ..."; keep the part after the location.
std::string parse_problem(const std::string& what) {
  const size_t at = what.find("parse error");
  const size_t colon = at == std::string::npos ? at : what.find(": ", at);
  return colon == std::string::npos ? what : what.substr(colon + 2);
}

}  // namespace

std::string in_quotes(const std::string& s) {
  return "\"" + s + "\"";
}

std::string join(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& item : items) out += (out.empty() ? "" : ", ") + item;
  return out;
}

std::string describe(const json& value) {
  constexpr size_t kMaxShown = 40;
  switch (value.type()) {
    case json::value_t::null:
      return "null";
    case json::value_t::boolean:
      return value.dump() + " (a boolean)";
    case json::value_t::string: {
      std::string text = value.dump();
      if (text.size() > kMaxShown) text = text.substr(0, kMaxShown) + "...\"";
      return text + " (a string)";
    }
    case json::value_t::array:
      return "an array of " + std::to_string(value.size()) + " elements";
    case json::value_t::object:
      return "an object";
    default:
      return value.dump();  // the numbers
  }
}

std::string suggestion(const std::string& word, const std::vector<std::string>& candidates) {
  std::string best;
  size_t best_distance = 3;
  for (const std::string& candidate : candidates) {
    const size_t d = edit_distance(word, candidate);
    if (d < best_distance && d < candidate.size()) {
      best = candidate;
      best_distance = d;
    }
  }
  return best.empty() ? "" : " (did you mean " + in_quotes(best) + "?)";
}

std::string child(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

std::string element(const std::string& path, size_t index) {
  return path + "[" + std::to_string(index) + "]";
}

json Checker::parse(const std::string& text) const {
  DuplicateKeyCheck duplicates;
  const json::parser_callback_t callback = [&](int /*depth*/, json::parse_event_t event,
                                               json& parsed) {
    const std::string repeated = duplicates.on_event(event, parsed);
    if (!repeated.empty()) fail(repeated, "duplicate key; each field may appear once");
    return true;
  };
  try {
    return json::parse(text, callback);
  } catch (const json::parse_error& e) {
    fail(line_and_column(text, e.byte), "invalid JSON: " + parse_problem(e.what()));
  } catch (const json::out_of_range& e) {
    // A literal beyond double range (1e400): nlohmann names the literal but not where it is.
    const std::string what = e.what();
    const size_t open = what.find('\''), close = what.rfind('\'');
    const std::string literal = open < close ? what.substr(open + 1, close - open - 1) : "";
    const size_t at = literal.empty() ? std::string::npos : text.find(literal);
    fail(at == std::string::npos ? "(a number)" : line_and_column(text, at + 1),
           "number " + (literal.empty() ? std::string("literal") : literal) +
               " is beyond the range of a double (about 1.8e308)");
  }
}

}  // namespace checked_json
}  // namespace sigmafem
