// libFuzzer harness: the point-cloud CSV reader on arbitrary bytes, and the frames' placement
// on a step grid of 100 rows (what estimate does next with a file it has read).
#include <cstddef>
#include <cstdint>

#include "host/common/input_error.h"
#include "host/data/point_cloud_table.h"
#include "tests/fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const std::string path = sigmafem::fuzz::input_file(data, size, "pointcloud.csv");
    const sigmafem::PointCloudTable table = sigmafem::read_point_cloud_csv(path);
    sigmafem::frames_by_step(table, 0.01, 100, path);
  } catch (const sigmafem::InputError&) {
  }
  return 0;
}
