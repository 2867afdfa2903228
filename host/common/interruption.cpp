#include "host/common/interruption.h"

#include <csignal>
#include <string>

namespace sigmafem {

namespace {

volatile std::sig_atomic_t g_signal = 0;

// Records the signal and restores the default action, so that a second Ctrl-C ends a run at
// once where no loop checks (a hung device, a long mesh refinement).
extern "C" void record_signal(int signal_number) {
  g_signal = signal_number;
  std::signal(signal_number, SIG_DFL);
}

}  // namespace

Interrupted::Interrupted(int signal_number)
    : std::runtime_error("interrupted by signal " + std::to_string(signal_number) +
                         "; nothing was written under the output's final names"),
      signal_number_(signal_number) {}

void install_interruption_handlers() {
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) std::signal(signal_number, record_signal);
}

void throw_if_interrupted() {
  if (g_signal != 0) throw Interrupted(g_signal);
}

}  // namespace sigmafem
