// check_input_file / read_input_file: the one gate every reader of a user's file goes through.
// It refuses what is not a regular file (a folder, a named pipe, /dev/zero, a socket, a link to
// one of these) and files larger than the reader's limit, so that no reader blocks or grows
// without end, and every refusal is an InputError "<prefix>: <what is wrong>".
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace sigmafem {

// Limits by kind of input: generous for what sigmafem runs, far below what memory holds.
constexpr std::uintmax_t kMaxJsonBytes = 64ull << 20;   // a scenario, truth.json
constexpr std::uintmax_t kMaxMeshBytes = 2ull << 30;    // millions of tetrahedra in ASCII
constexpr std::uintmax_t kMaxTableBytes = 4ull << 30;   // observations, truth, trajectories

// Throws unless `path` is, after links, a regular file of at most `max_bytes`.
void check_input_file(const std::string& path, const std::string& prefix, std::uintmax_t max_bytes);

// The whole file, after check_input_file; also stops at `max_bytes` should the file grow.
std::string read_input_file(const std::string& path, const std::string& prefix,
                            std::uintmax_t max_bytes);

// The text without a leading UTF-8 byte order mark (some Windows editors write one).
std::string_view without_byte_order_mark(std::string_view text);

}  // namespace sigmafem
