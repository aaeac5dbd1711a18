#pragma once
// Internal: the address space a process may still map under `ulimit -v` (RLIMIT_AS), where
// allocations fail long before the machine's memory runs out.
#include <cstdint>

namespace dgtex::detail {

// The limit less the process's virtual size (/proc/self/statm); -1 without a limit.
std::int64_t address_space_left();

}  // namespace dgtex::detail
