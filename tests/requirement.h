// What a test needs that a machine may lack (an OpenCL or Vulkan device, fp64 on it, gnuplot,
// the Vulkan validation layer, the shared data): without it the test skips, and ctest counts a
// skip as a pass. The test command (setup.sh test) sets SIGMAFEM_TESTS_REQUIRE=all, under which
// a missing requirement fails the test instead, so that a machine that lost its driver cannot
// pass the suite with half of it skipped.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>

namespace sigmafem::test {

inline bool requirements_enforced() {
  const char* value = std::getenv("SIGMAFEM_TESTS_REQUIRE");
  return value != nullptr && std::string(value) == "all";
}

}  // namespace sigmafem::test

// Skips the test with `why`, or fails it under SIGMAFEM_TESTS_REQUIRE=all. `why` may be a
// chain of << operands.
#define SIGMAFEM_MISSING(why)                                                                 \
  do {                                                                                        \
    if (::sigmafem::test::requirements_enforced()) {                                          \
      GTEST_FAIL() << why << " (a failure, not a skip: SIGMAFEM_TESTS_REQUIRE=all)";          \
    } else {                                                                                  \
      GTEST_SKIP() << why;                                                                    \
    }                                                                                         \
  } while (false)
