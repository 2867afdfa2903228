// The interruption handlers: one stop request, even when the signal arrives twice at once,
// unwinds the run cleanly; a second request later ends it at once.
#include "host/common/interruption.h"

#include <gtest/gtest.h>

#include <chrono>
#include <csignal>
#include <thread>

namespace sigmafem {
namespace {

// `timeout` and a shell's job control send the signal to the program and then to its process
// group: both arrive within microseconds. Each raise() here runs the handler before it returns.
TEST(InterruptionTest, ASignalTwiceAtOnceIsOneRequestToStopCleanly) {
  install_interruption_handlers();
  std::raise(SIGTERM);
  std::raise(SIGTERM);
  try {
    throw_if_interrupted();
    FAIL() << "no Interrupted after SIGTERM";
  } catch (const Interrupted& stop) {
    EXPECT_EQ(stop.signal_number(), SIGTERM);
  }
}

// A second Ctrl-C, well after the first, is for a run stuck where no loop checks: it ends the
// program at once with the signal's default action.
TEST(InterruptionDeathTest, ASecondSignalLaterEndsTheRunAtOnce) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        install_interruption_handlers();
        std::raise(SIGINT);
        std::this_thread::sleep_for(std::chrono::milliseconds(700));
        std::raise(SIGINT);
        std::exit(0);  // not reached: the second SIGINT kills
      },
      testing::KilledBySignal(SIGINT), "");
}

}  // namespace
}  // namespace sigmafem
