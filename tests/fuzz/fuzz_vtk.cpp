// libFuzzer harness: the legacy VTK reader (ASCII and binary) on arbitrary bytes.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "host/common/input_error.h"
#include "host/mesh/mesh_formats.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    sigmafem::read_vtk(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.vtk");
  } catch (const sigmafem::InputError&) {
  }
  return 0;
}
