#include "host/common/progress.h"

#include <unistd.h>

#include <cstdio>
#include <utility>

#include "host/common/interruption.h"

namespace sigmafem {

Progress::Progress(std::string label, long long total, bool enabled)
    : label_(std::move(label)),
      total_(total),
      active_(enabled && isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_(start_ - std::chrono::seconds(1)) {}

void Progress::update(long long done, const std::string& detail) {
  throw_if_interrupted();   // every long loop reports progress: where Ctrl-C takes effect
  if (!active_) return;
  const auto now = std::chrono::steady_clock::now();
  if (done < total_ && now - last_ < std::chrono::milliseconds(200)) return;
  last_ = now;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double fraction = total_ > 0 ? static_cast<double>(done) / static_cast<double>(total_) : 1.0;
  const double remaining = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : 0.0;
  std::fprintf(stderr, "\r%s %lld/%lld (%3.0f%%) %.1f s elapsed, %.1f s left %s\033[K",
               label_.c_str(), done, total_, 100.0 * fraction, elapsed, remaining, detail.c_str());
  std::fflush(stderr);
}

void Progress::finish() {
  if (!active_) return;
  std::fprintf(stderr, "\r\033[K");
  std::fflush(stderr);
}

}  // namespace sigmafem
