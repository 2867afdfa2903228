// libFuzzer harness: load_scenario on arbitrary bytes (a scenario JSON beside box.msh).
#include <cstddef>
#include <cstdint>

#include "host/common/input_error.h"
#include "host/scenario/scenario.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    sigmafem::load_scenario(sigmafem::fuzz::input_file(data, size, "scenario.json"));
  } catch (const sigmafem::InputError&) {
  }
  return 0;
}
