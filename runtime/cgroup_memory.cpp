#include "cgroup_memory.h"

#include <algorithm>
#include <fstream>

namespace dgtex::detail {
namespace {

// The file's first number; -1 when it holds none (v2's "max").
std::int64_t first_number(const std::string& path) {
  std::ifstream file(path);
  long long value = -1;
  if (!(file >> value)) return -1;
  return value;
}

}  // namespace

std::int64_t cgroup_memory_left(const std::string& limit_file, const std::string& usage_file) {
  const std::int64_t no_limit = std::int64_t{1} << 60;
  const std::int64_t limit = first_number(limit_file), usage = first_number(usage_file);
  if (!(limit > 0 && limit < no_limit && usage >= 0)) return -1;
  return std::max<std::int64_t>(0, limit - usage);
}

}  // namespace dgtex::detail
