// TextCursor: walks through the text of a mesh file, line by line (Gmsh) or token by token
// with binary blocks in between (legacy VTK), and keeps the line number so that every error
// can say where it happened. Shared by the mesh readers; not part of the public mesh API.
//
// Conventions: line numbers are 1-based and count every '\n' byte, binary blocks included,
// so they agree with `sed -n <N>p` and with an editor. A line's end is "\n" or "\r\n" (files
// saved on Windows read the same). Numbers are parsed with std::from_chars: independent of
// the locale, no silent partial parse ("1.5x" is an error, not 1.5), and NaN or infinity is
// rejected. Every error is an InputError "mesh <source>: line <N>: <what>".
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace sigmafem {

// Throws InputError "mesh <source>: <what>" (for errors that belong to no line).
[[noreturn]] void throw_mesh_error(const std::string& source, const std::string& what);

// `text` shortened to at most 40 characters, non-printable bytes shown as '?', in quotes:
// for quoting what was found in an error message without flooding it with binary garbage.
std::string quote_for_message(std::string_view text);

class TextCursor {
 public:
  // `text` must outlive the cursor; `source` is the file name used in messages.
  TextCursor(std::string_view text, std::string source);

  const std::string& source() const { return source_; }
  // Line of the last line, token or block returned (0 before the first).
  int line() const { return line_; }
  // True when everything has been consumed.
  bool at_end() const { return pos_ >= text_.size(); }

  // The next line without its end-of-line; nullopt at the end of the text.
  std::optional<std::string_view> next_line();
  // The next line; at the end of the text, fails with "file ends ...: expected <expected>".
  std::string_view require_line(const std::string& expected);
  // The next line that is not blank (Gmsh allows blank lines between sections).
  std::optional<std::string_view> next_nonblank_line();

  // The next whitespace-separated token, crossing lines; empty at the end of the text.
  std::string_view next_token();
  // The next token; at the end of the text, fails naming what was expected.
  std::string_view require_token(const std::string& expected);
  // Consumes the rest of the current line including its '\n', failing if anything but
  // blanks is there: in legacy VTK binary data starts right after the keyword's line.
  void finish_line();
  // The next `count` raw bytes; fails (without reading) if fewer remain.
  std::string_view read_bytes(std::size_t count, const std::string& expected);
  // Bytes not yet consumed: an upper bound for counts read from the file, so that a
  // corrupt count cannot make a reader reserve gigabytes.
  std::size_t remaining() const { return text_.size() - pos_; }

  // Throws InputError "mesh <source>: line <line()>: <what>".
  [[noreturn]] void fail(const std::string& what) const;
  // Throws InputError "mesh <source>: line <line>: <what>" for an earlier line.
  [[noreturn]] void fail_at(int line, const std::string& what) const;
  // Throws "mesh <source>: file ends after line <N>: expected <expected>" (a truncated file).
  [[noreturn]] void fail_at_end(const std::string& expected) const;

 private:
  std::string_view text_;
  std::string source_;
  std::size_t pos_ = 0;
  int line_ = 0;       // line of the last item returned
  int next_line_ = 1;  // line on which pos_ stands
};

// Splits a line at blanks (spaces, tabs) into tokens that view into `line`.
std::vector<std::string_view> split_fields(std::string_view line);

// Parse one field of the file; on failure `at.fail()` says "expected <what>, found "<field>"".
double parse_real(std::string_view field, const TextCursor& at, const char* what);
long long parse_integer(std::string_view field, const TextCursor& at, const char* what);
// An integer that must lie in [min_value, max_value] (counts, indices that must fit an int).
long long parse_integer_in(std::string_view field, long long min_value, long long max_value,
                           const TextCursor& at, const char* what);

}  // namespace sigmafem
