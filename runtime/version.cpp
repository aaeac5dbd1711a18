#include "dgtex/version.h"

namespace dgtex {

// DGTEX_VERSION is defined for this file alone (CMakeLists.txt), so that a new version
// recompiles one file.
const char* version() noexcept { return DGTEX_VERSION; }

}  // namespace dgtex
