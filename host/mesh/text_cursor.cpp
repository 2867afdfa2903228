// TextCursor and field parsing for the mesh readers (see text_cursor.h).
#include "host/mesh/text_cursor.h"

#include <charconv>
#include <cmath>
#include <system_error>
#include <utility>

#include "host/common/input_error.h"

namespace sigmafem {

namespace {

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }
bool is_space(char c) { return is_blank(c) || c == '\n'; }

// Longest piece of a found value quoted in a message; a binary file would flood it otherwise.
constexpr std::size_t kQuoteLength = 40;

}  // namespace

void throw_mesh_error(const std::string& source, const std::string& what) {
  throw InputError("mesh " + source + ": " + what);
}

std::string quote_for_message(std::string_view text) {
  std::string quoted = "\"";
  for (std::size_t i = 0; i < text.size() && i < kQuoteLength; ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    quoted += (c >= 0x20 && c < 0x7f) ? static_cast<char>(c) : '?';
  }
  if (text.size() > kQuoteLength) quoted += "...";
  return quoted + "\"";
}

TextCursor::TextCursor(std::string_view text, std::string source)
    : text_(text), source_(std::move(source)) {}

std::optional<std::string_view> TextCursor::next_line() {
  if (at_end()) return std::nullopt;
  const std::size_t newline = text_.find('\n', pos_);
  const std::size_t stop = newline == std::string_view::npos ? text_.size() : newline;
  std::string_view line = text_.substr(pos_, stop - pos_);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  line_ = next_line_;
  if (newline != std::string_view::npos) ++next_line_;
  pos_ = newline == std::string_view::npos ? text_.size() : newline + 1;
  return line;
}

std::string_view TextCursor::require_line(const std::string& expected) {
  const std::optional<std::string_view> line = next_line();
  if (!line) fail_at_end(expected);
  return *line;
}

std::optional<std::string_view> TextCursor::next_nonblank_line() {
  while (std::optional<std::string_view> line = next_line()) {
    if (!split_fields(*line).empty()) return line;
  }
  return std::nullopt;
}

std::string_view TextCursor::next_token() {
  while (pos_ < text_.size() && is_space(text_[pos_])) {
    if (text_[pos_] == '\n') ++next_line_;
    ++pos_;
  }
  const std::size_t start = pos_;
  while (pos_ < text_.size() && !is_space(text_[pos_])) ++pos_;
  if (pos_ > start) line_ = next_line_;
  return text_.substr(start, pos_ - start);
}

std::string_view TextCursor::require_token(const std::string& expected) {
  const std::string_view token = next_token();
  if (token.empty()) fail_at_end(expected);
  return token;
}

void TextCursor::finish_line() {
  while (pos_ < text_.size() && text_[pos_] != '\n') {
    if (!is_blank(text_[pos_])) {
      fail("unexpected " + quote_for_message(text_.substr(pos_)) + " at the end of the line");
    }
    ++pos_;
  }
  if (pos_ < text_.size()) {
    ++pos_;
    ++next_line_;
  }
}

std::string_view TextCursor::read_bytes(std::size_t count, const std::string& expected) {
  if (count > remaining()) {
    fail_at_end(expected + " (" + std::to_string(count) + " bytes; " + std::to_string(remaining()) +
                " left)");
  }
  const std::string_view block = text_.substr(pos_, count);
  line_ = next_line_;
  for (const char c : block) {
    if (c == '\n') ++next_line_;
  }
  pos_ += count;
  return block;
}

void TextCursor::fail(const std::string& what) const { fail_at(line_, what); }

void TextCursor::fail_at(int line, const std::string& what) const {
  throw_mesh_error(source_, "line " + std::to_string(line) + ": " + what);
}

void TextCursor::fail_at_end(const std::string& expected) const {
  throw_mesh_error(source_, "file ends after line " + std::to_string(line_) +
                                " (truncated?): expected " + expected);
}

std::vector<std::string_view> split_fields(std::string_view line) {
  std::vector<std::string_view> fields;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && is_blank(line[i])) ++i;
    const std::size_t start = i;
    while (i < line.size() && !is_blank(line[i])) ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

namespace {

[[noreturn]] void fail_field(std::string_view field, const TextCursor& at, const char* what) {
  at.fail(std::string("expected ") + what + ", found " + quote_for_message(field));
}

// from_chars does not accept the leading '+' that some writers put before positive numbers.
std::string_view strip_plus(std::string_view field) {
  if (field.size() > 1 && field.front() == '+') field.remove_prefix(1);
  return field;
}

}  // namespace

double parse_real(std::string_view field, const TextCursor& at, const char* what) {
  const std::string_view digits = strip_plus(field);
  double value = 0.0;
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (error != std::errc{} || end != digits.data() + digits.size() || !std::isfinite(value)) {
    fail_field(field, at, what);
  }
  return value;
}

long long parse_integer(std::string_view field, const TextCursor& at, const char* what) {
  const std::string_view digits = strip_plus(field);
  long long value = 0;
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (error != std::errc{} || end != digits.data() + digits.size()) fail_field(field, at, what);
  return value;
}

long long parse_integer_in(std::string_view field, long long min_value, long long max_value,
                           const TextCursor& at, const char* what) {
  const long long value = parse_integer(field, at, what);
  if (value < min_value || value > max_value) {
    at.fail(std::string("expected ") + what + " between " + std::to_string(min_value) + " and " +
            std::to_string(max_value) + ", found " + std::to_string(value));
  }
  return value;
}

}  // namespace sigmafem
