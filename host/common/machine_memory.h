// The machine's physical memory, for refusing a run whose tables could not fit before
// allocating them (generate's tables, a point cloud's data matrix), naming the field or file
// that sets their size.
#pragma once

#include <unistd.h>

namespace sigmafem {

// Bytes of physical memory; 0 when the system does not say.
inline double physical_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page_size = ::sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page_size > 0 ? static_cast<double>(pages) * static_cast<double>(page_size) : 0.0;
}

}  // namespace sigmafem
