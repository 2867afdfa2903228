// The shared element math (kernels/shared/element.h) for C++, in double precision, inside
// namespace sigmafem::shared. Include this, never element.h directly, so that the shared
// header is compiled once in one namespace (STYLE.md).
#pragma once

#include <cmath>

namespace sigmafem::shared {
#include "element.h"
}  // namespace sigmafem::shared
