#pragma once
// The process's virtual size as the address-space limit (RLIMIT_AS, `ulimit -v`) counts it,
// for tests that set the limit a little above it.
#include <unistd.h>

#include <cstdint>
#include <fstream>

namespace dgtex::test {

// Bytes; -1 without /proc/self/statm.
inline std::int64_t virtual_size_bytes() {
  std::ifstream statm("/proc/self/statm");
  long long pages = 0;
  if (!(statm >> pages)) return -1;
  return static_cast<std::int64_t>(pages) * sysconf(_SC_PAGESIZE);
}

}  // namespace dgtex::test
