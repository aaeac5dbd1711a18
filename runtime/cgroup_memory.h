#pragma once
// The room left under a container's memory limit (its cgroup's), which can be far below the
// host's memory that /proc/meminfo reports. Internal to available_memory_bytes.
#include <cstdint>
#include <string>

namespace dgtex::detail {

// cgroup v2's and v1's files of the group at the root of the mount: a container's own (under
// cgroup namespaces), not a group nested below it.
inline constexpr const char* kCgroupV2LimitFile = "/sys/fs/cgroup/memory.max";
inline constexpr const char* kCgroupV2UsageFile = "/sys/fs/cgroup/memory.current";
inline constexpr const char* kCgroupV1LimitFile = "/sys/fs/cgroup/memory/memory.limit_in_bytes";
inline constexpr const char* kCgroupV1UsageFile = "/sys/fs/cgroup/memory/memory.usage_in_bytes";

// The limit less the usage in bytes (0 when the usage has reached it), from one version's
// two files; -1 when there is no limit (v2 writes "max", v1 a number near 2^63) or a file
// is missing or unreadable.
std::int64_t cgroup_memory_left(const std::string& limit_file, const std::string& usage_file);

}  // namespace dgtex::detail
