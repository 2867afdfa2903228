// What the harnesses share: the readers take a path, so each input is written to a file in a
// folder of the process's own (beside a copy of the box mesh, which scenario inputs name), and
// InputError, the readers' answer to bad input, is the expected outcome; anything else that
// escapes (another exception, a crash, a sanitizer report) is a finding.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

namespace sigmafem::fuzz {

// The folder, made at the first input and removed when the process exits normally (libFuzzer
// exits so at the end of its time; a crash leaves it, with the input that crashed).
inline const std::filesystem::path& work_folder() {
  static const std::filesystem::path folder = [] {
    const std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("sigmafem_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(path);
    if (const char* mesh = std::getenv("SIGMAFEM_FUZZ_MESH"))
      std::filesystem::copy_file(mesh, path / "box.msh", std::filesystem::copy_options::overwrite_existing);
    return path;
  }();
  // Registered after `folder` is made, so it runs before `folder` is destroyed.
  static const int removed_at_exit = std::atexit([] {
    std::error_code ignored;
    std::filesystem::remove_all(work_folder(), ignored);
  });
  (void)removed_at_exit;
  return folder;
}

// Writes the input to `name` in the work folder and returns its path.
inline std::string input_file(const uint8_t* data, size_t size, const std::string& name) {
  const std::string path = (work_folder() / name).string();
  std::ofstream(path, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data),
                                                                static_cast<std::streamsize>(size));
  return path;
}

}  // namespace sigmafem::fuzz
