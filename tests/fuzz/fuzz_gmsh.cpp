// libFuzzer harness: the Gmsh reader (1.0, 2.2, 4.1) on arbitrary text.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "host/common/input_error.h"
#include "host/mesh/mesh_formats.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    sigmafem::read_gmsh(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.msh");
  } catch (const sigmafem::InputError&) {
  }
  return 0;
}
