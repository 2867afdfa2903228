#include "host/common/atomic_file.h"

#include <cstdio>
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

void AtomicFile::commit() {
  out_.flush();
  const bool ok = static_cast<bool>(out_);
  out_.close();
  if (!ok) throw InputError(path_ + ": write failed (disk full?)");
  if (std::rename(temporary_path_.c_str(), path_.c_str()) != 0)
    throw InputError(path_ + ": cannot rename " + temporary_path_ + " into place");
  committed_ = true;
}

void write_file_atomically(const std::string& path, const std::string& text) {
  AtomicFile file(path);
  file.stream() << text;
  file.commit();
}

}  // namespace sigmafem
