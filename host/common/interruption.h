// Interruption: SIGINT (Ctrl-C), SIGTERM and SIGHUP end a run cleanly. The handler only records
// the signal; the long loops (every Progress::update, every filter step) call
// throw_if_interrupted(), whose exception unwinds the run, so that destructors remove staging
// folders and temporary files (host/common/output_set.h), and main exits 128 + the signal.
// A second signal, more than half a second after the first, takes the default action at once
// (for a run stuck where no loop checks); a repeat within that time is the same request (the
// signal sent to the program and then to its process group, as `timeout` does).
#pragma once

#include <stdexcept>

namespace sigmafem {

class Interrupted : public std::runtime_error {
 public:
  explicit Interrupted(int signal_number);
  int signal_number() const { return signal_number_; }

 private:
  int signal_number_;
};

// Installs the handlers (once, from main).
void install_interruption_handlers();

// Throws Interrupted if a signal came since the handlers were installed.
void throw_if_interrupted();

}  // namespace sigmafem
