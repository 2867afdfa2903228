// AtomicFile: write an output file under a temporary name and rename it into place when it
// is complete, so that a crash or an error never leaves a half-written file behind.
#pragma once

#include <fstream>
#include <string>

namespace sigmafem {

class AtomicFile {
 public:
  // Opens `path + ".partial"` for writing; throws InputError if it cannot (a path problem).
  // commit() throws std::runtime_error when writing or renaming fails (a full disk).
  explicit AtomicFile(std::string path);
  // Removes the temporary file if commit() was not called.
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  std::ofstream& stream() { return out_; }
  // Flushes, checks the stream and renames the temporary file to its final name.
  void commit();

 private:
  std::string path_;
  std::string temporary_path_;
  std::ofstream out_;
  bool committed_ = false;
};

// Writes `text` to `path` atomically.
void write_file_atomically(const std::string& path, const std::string& text);

}  // namespace sigmafem
