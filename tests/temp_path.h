// unique_temp_path: a path in the temporary folder that no other test process uses. ctest
// runs tests in parallel processes; a fixed name would let one test delete another's files.
#pragma once

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <string>

namespace sigmafem::test {

inline std::filesystem::path unique_temp_path(const std::string& stem) {
  static std::atomic<int> counter{0};
  return std::filesystem::temp_directory_path() /
         (stem + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
}

}  // namespace sigmafem::test
