#include "host/common/atomic_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <utility>

#include "host/common/input_error.h"

namespace sigmafem {

AtomicFile::AtomicFile(std::string path)
    : path_(std::move(path)), temporary_path_(path_ + ".partial") {
  out_.open(temporary_path_, std::ios::out | std::ios::trunc | std::ios::binary);
  if (!out_) throw InputError(path_ + ": cannot open for writing");
}

AtomicFile::~AtomicFile() {
  if (!committed_) {
    out_.close();
    std::remove(temporary_path_.c_str());
  }
}

// A failure to write is the machine's (a full disk, a lost mount), not the input's: a
// runtime_error (exit 1), where a path that cannot be opened is an InputError (exit 2).
void AtomicFile::commit() {
  out_.flush();
  out_.close();   // close flushes the last buffer: its failure counts too
  if (out_.fail()) throw std::runtime_error(path_ + ": write failed (disk full?)");
  if (std::rename(temporary_path_.c_str(), path_.c_str()) != 0)
    throw std::runtime_error(path_ + ": cannot rename " + temporary_path_ + " into place: " +
                             std::strerror(errno));
  committed_ = true;
}

void write_file_atomically(const std::string& path, const std::string& text) {
  AtomicFile file(path);
  file.stream() << text;
  file.commit();
}

}  // namespace sigmafem
