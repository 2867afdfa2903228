// Progress: a one-line progress report on stderr for long runs, redrawn in place at most
// five times a second, and only when stderr is a terminal (logs and CI stay clean).
#pragma once

#include <chrono>
#include <string>

namespace sigmafem {

class Progress {
 public:
  // `enabled` false (or stderr not a terminal) makes every call a no-op.
  Progress(std::string label, long long total, bool enabled);
  // Reports `done` of `total`; `detail` is appended (e.g. "CG 12 it"). Throws Interrupted
  // after SIGINT/SIGTERM/SIGHUP (host/common/interruption.h), shown or not.
  void update(long long done, const std::string& detail = "");
  // Clears the line.
  void finish();

 private:
  std::string label_;
  long long total_;
  bool active_;
  std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace sigmafem
