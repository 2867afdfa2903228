// The shipped scenarios' folder, for tests that load them by name.
#pragma once

#include <string>

namespace sigmafem {

inline const std::string kScenarios = std::string(SIGMAFEM_SOURCE_DIR) + "/scenarios/";

}  // namespace sigmafem
