// unique_temp_path: a path in the temporary folder that no other test process uses. ctest
// runs tests in parallel processes; a fixed name would let one test delete another's files.
#pragma once

#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>

namespace sigmafem::test {

inline std::filesystem::path unique_temp_path(const std::string& stem) {
  static std::atomic<int> counter{0};
  return std::filesystem::temp_directory_path() /
         (stem + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
}

// A fresh folder under the system temporary folder, removed with everything in it.
class TempDir {
 public:
  explicit TempDir(const std::string& stem = "sigmafem_test") : path_(unique_temp_path(stem)) {
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  std::string path() const { return path_.string(); }
  // The path of `name` in this folder.
  std::string file(const std::string& name) const { return (path_ / name).string(); }
  // Writes `text` byte for byte to `name` (creating subfolders) and returns its path.
  std::string write(const std::string& name, const std::string& text) const {
    std::filesystem::create_directories(std::filesystem::path(file(name)).parent_path());
    std::ofstream(file(name), std::ios::binary) << text;
    return file(name);
  }
  // Copies `from` to `name` in this folder (creating subfolders).
  void copy(const std::string& from, const std::string& name) const {
    std::filesystem::create_directories(std::filesystem::path(file(name)).parent_path());
    std::filesystem::copy_file(from, file(name), std::filesystem::copy_options::overwrite_existing);
  }

 private:
  std::filesystem::path path_;
};

}  // namespace sigmafem::test
