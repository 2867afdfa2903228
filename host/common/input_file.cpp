#include "host/common/input_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string_view>
#include <system_error>

#include "host/common/input_error.h"

namespace sigmafem {
namespace fs = std::filesystem;

namespace {

std::string megabytes(std::uintmax_t bytes) {
  return std::to_string((bytes + (1u << 20) - 1) >> 20) + " MB";
}

// What a path that is not a regular file is, in a user's words.
std::string kind_of(fs::file_type type) {
  switch (type) {
    case fs::file_type::directory:
      return "is a folder";
    case fs::file_type::fifo:
      return "is a named pipe (FIFO)";
    case fs::file_type::character:
      return "is a character device (such as /dev/zero)";
    case fs::file_type::block:
      return "is a block device";
    case fs::file_type::socket:
      return "is a socket";
    default:
      return "is not a regular file";
  }
}

}  // namespace

void check_input_file(const std::string& path, const std::string& prefix, std::uintmax_t max_bytes) {
  std::error_code error;
  const fs::file_status status = fs::status(path, error);  // follows links
  if (status.type() == fs::file_type::not_found) {
    const bool dangling = fs::is_symlink(fs::symlink_status(path, error));
    throw InputError(prefix + ": file not found" + (dangling ? " (a link to nothing)" : ""));
  }
  if (error) throw InputError(prefix + ": cannot read: " + error.message());
  if (status.type() != fs::file_type::regular)
    throw InputError(prefix + ": " + kind_of(status.type()) +
                     ", expected a regular file that can be read to its end");
  const std::uintmax_t size = fs::file_size(path, error);
  if (!error && size > max_bytes)
    throw InputError(prefix + ": the file is " + megabytes(size) + ", more than the " +
                     megabytes(max_bytes) + " a file of this kind may have");
}

std::string read_input_file(const std::string& path, const std::string& prefix,
                            std::uintmax_t max_bytes) {
  check_input_file(path, prefix, max_bytes);
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!file) throw InputError(prefix + ": cannot open: " + std::strerror(errno));
  std::string content;
  char buffer[1 << 16];
  std::size_t got = 0;
  while ((got = std::fread(buffer, 1, sizeof buffer, file.get())) > 0) {
    content.append(buffer, got);
    if (content.size() > max_bytes)
      throw InputError(prefix + ": the file grew past the " + megabytes(max_bytes) +
                       " a file of this kind may have while it was read");
  }
  if (std::ferror(file.get())) throw InputError(prefix + ": read error: " + std::strerror(errno));
  return content;
}

std::string_view without_byte_order_mark(std::string_view text) {
  constexpr std::string_view kMark = "\xEF\xBB\xBF";
  if (text.substr(0, kMark.size()) == kMark) text.remove_prefix(kMark.size());
  return text;
}

}  // namespace sigmafem
