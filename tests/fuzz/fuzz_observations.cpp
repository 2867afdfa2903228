// libFuzzer harness: the observations CSV reader on arbitrary bytes. The first byte picks the
// number of observed points (0 to 7), so that headers of every width are reached.
#include <cstddef>
#include <cstdint>

#include "host/common/input_error.h"
#include "host/data/observation_table.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  const int points = data[0] % 8;
  try {
    sigmafem::read_observations_csv(sigmafem::fuzz::input_file(data + 1, size - 1, "observations.csv"), points, 0.01);
  } catch (const sigmafem::InputError&) {
  }
  return 0;
}
