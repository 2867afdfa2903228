// libFuzzer harness: the truth CSV reader on arbitrary bytes.
#include <cstddef>
#include <cstdint>

#include "host/common/input_error.h"
#include "host/data/truth_table.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    sigmafem::read_truth_csv(sigmafem::fuzz::input_file(data, size, "truth.csv"));
  } catch (const sigmafem::InputError&) {
  }
  return 0;
}
