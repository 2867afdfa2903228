#include "host/common/interruption.h"

#include <csignal>
#include <ctime>
#include <string>

namespace sigmafem {

namespace {

volatile std::sig_atomic_t g_signal = 0;
// When the first signal came, in whole and fractional monotonic seconds.
volatile std::sig_atomic_t g_first_seconds = 0;
volatile std::sig_atomic_t g_first_millis = 0;

// A repeat within this time is the same request: `timeout`, and a shell's job control, send
// the signal to the program and then to its whole process group, so one stop arrives twice.
constexpr long kSameRequestMillis = 500;

long monotonic_millis(const timespec& t) { return static_cast<long>(t.tv_sec) * 1000 + t.tv_nsec / 1000000; }

// Records the first signal. A later one (a second Ctrl-C, more than kSameRequestMillis after
// the first) ends the run at once with the default action, for a run stuck where no loop
// checks (a hung device, a long mesh refinement). Only async-signal-safe calls here.
extern "C" void record_signal(int signal_number) {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  if (g_signal == 0) {
    g_first_seconds = static_cast<std::sig_atomic_t>(now.tv_sec);
    g_first_millis = static_cast<std::sig_atomic_t>(now.tv_nsec / 1000000);
    g_signal = signal_number;
    return;
  }
  timespec first{};
  first.tv_sec = g_first_seconds;
  first.tv_nsec = static_cast<long>(g_first_millis) * 1000000;
  if (monotonic_millis(now) - monotonic_millis(first) < kSameRequestMillis) return;
  // The signal is blocked while its handler runs: raise() delivers it, with the default
  // action, as soon as the handler returns.
  struct sigaction default_action {};
  default_action.sa_handler = SIG_DFL;
  sigemptyset(&default_action.sa_mask);
  sigaction(signal_number, &default_action, nullptr);
  raise(signal_number);
}

}  // namespace

Interrupted::Interrupted(int signal_number)
    : std::runtime_error("interrupted by signal " + std::to_string(signal_number) +
                         "; nothing was written under the output's final names"),
      signal_number_(signal_number) {}

void install_interruption_handlers() {
  struct sigaction action {};
  action.sa_handler = record_signal;
  sigemptyset(&action.sa_mask);
  // While one handler runs, the others wait: the first signal's record is never torn.
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&action.sa_mask, signal_number);
  action.sa_flags = SA_RESTART;
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP}) sigaction(signal_number, &action, nullptr);
}

void throw_if_interrupted() {
  if (g_signal != 0) throw Interrupted(g_signal);
}

}  // namespace sigmafem
