#include "dgtex/texel_memory_estimate.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "address_space.h"
#include "cgroup_memory.h"
#include "dgtex/scene_io.h"

namespace dgtex {
namespace {

std::int64_t active_texels_per_tile(ElementType type, int resolution) {
  const std::int64_t t = resolution;
  return type == ElementType::tri6 ? t * (t + 1) / 2 : t * t;
}

// "key: value kB" of /proc/meminfo in bytes; -1 when missing.
std::int64_t meminfo_bytes(const std::string& text, const std::string& key) {
  const std::size_t at = text.find("\n" + key + ":");
  if (at == std::string::npos) return -1;
  long long kib = -1;
  if (std::sscanf(text.c_str() + at + key.size() + 2, "%lld", &kib) != 1) return -1;
  return static_cast<std::int64_t>(kib) * 1024;
}

// The bound's bytes a texel of a cut's region: its Laplace solves decide it.
std::int64_t cut_bytes_per_texel(const TexelFields& fields) {
  return fields.graph_solves ? kGraphSolveBytesPerTexel : kFieldBytesPerTexel;
}

std::string count_of(int n, const std::string& noun) { return std::to_string(n) + " " + noun + (n == 1 ? "" : "s"); }

// DGTEX_MEMORY_LIMIT_MB as bytes; -1 when unset or empty. Throws std::invalid_argument for
// anything but a whole number of MiB >= 1.
std::int64_t memory_limit_from_environment() {
  const char* text = std::getenv("DGTEX_MEMORY_LIMIT_MB");
  if (!text || !*text) return -1;
  char* end = nullptr;
  errno = 0;
  const long long mib = std::strtoll(text, &end, 10);
  if (*end != '\0' || errno == ERANGE || mib < 1 || mib > (std::int64_t{1} << 40))
    throw std::invalid_argument(std::string("DGTEX_MEMORY_LIMIT_MB = '") + text +
                                "': expected a whole number of MiB from 1 to " + std::to_string(std::int64_t{1} << 40) +
                                " (or unset: the machine's memory)");
  return static_cast<std::int64_t>(mib) << 20;
}

}  // namespace

std::int64_t texel_memory_lower_bound(const TexelFields& fields) {
  const std::int64_t per_tile = active_texels_per_tile(fields.type, fields.resolution);
  return per_tile * (fields.cuts.region_elements * cut_bytes_per_texel(fields) +
                     fields.creases.region_elements * kFieldBytesPerTexel);
}

std::string memory_size_text(std::int64_t bytes) {
  constexpr std::int64_t gib = std::int64_t{1} << 30;
  if (bytes < gib) return std::to_string(bytes >> 20) + " MiB";
  char text[32];
  std::snprintf(text, sizeof text, "%.1f GiB", static_cast<double>(bytes) / gib);
  return text;
}

std::int64_t available_memory_bytes() {
  std::int64_t bytes = -1;  // the least of the figures that are known
  auto cap = [&](std::int64_t figure) {
    if (figure >= 0) bytes = bytes < 0 ? figure : std::min(bytes, figure);
  };
  cap(memory_limit_from_environment());
  cap(detail::address_space_left());
  std::ifstream meminfo("/proc/meminfo");
  if (!meminfo) return bytes;
  std::stringstream text;
  text << "\n" << meminfo.rdbuf();
  const std::int64_t available = meminfo_bytes(text.str(), "MemAvailable");
  if (available < 0) return bytes;
  cap(available + std::max<std::int64_t>(0, meminfo_bytes(text.str(), "SwapFree")));
  cap(detail::cgroup_memory_left(detail::kCgroupV2LimitFile, detail::kCgroupV2UsageFile));
  cap(detail::cgroup_memory_left(detail::kCgroupV1LimitFile, detail::kCgroupV1UsageFile));
  return bytes;
}

void check_texel_memory(const TexelFields& fields, std::int64_t available_bytes, const std::string& source_name) {
  if (available_bytes < 0) return;
  const std::int64_t needed = texel_memory_lower_bound(fields);
  if (needed <= available_bytes) return;
  int fitting = 0;  // the largest power of two below T whose bound fits
  for (int t = fields.resolution / 2; t >= 8 && fitting == 0; t /= 2) {
    TexelFields smaller = fields;
    smaller.resolution = t;
    if (texel_memory_lower_bound(smaller) <= available_bytes) fitting = t;
  }
  std::string what;
  if (fields.cuts.fields > 0)
    what = count_of(fields.cuts.fields, "cut segment") + " (" + std::to_string(fields.cuts.region_elements) +
           " element regions, " + std::to_string(cut_bytes_per_texel(fields)) +
           " bytes a texel with " + (fields.graph_solves ? "texel-graph" : "tile multigrid") + " Laplace solves)";
  if (fields.creases.fields > 0)
    what += (what.empty() ? "" : " and ") + count_of(fields.creases.fields, "crease") + " (" +
            std::to_string(fields.creases.region_elements) + " element regions, " +
            std::to_string(kFieldBytesPerTexel) + " bytes a texel)";
  const std::string t = std::to_string(fields.resolution);
  const std::string problem = "the texel fields of " + what + " at " + t + " x " + t + " texels an element need at least " +
                              memory_size_text(needed) + ", more than the " + memory_size_text(available_bytes) +
                              " of memory available";
  const std::string valid = fitting > 0 ? "expected " + std::to_string(fitting) + " or less (the most that could fit on this machine)"
                                        : "no texture_resolution fits on this machine; fewer or shorter cuts or creases";
  throw SceneError(source_name, "enrichment.texture_resolution", problem, t, valid);
}

bool near_memory_limit(std::int64_t needed, std::int64_t available_bytes) {
  // Beyond the memory available the checks refuse the scene instead.
  return available_bytes >= 0 && 2 * needed > available_bytes && needed <= available_bytes;
}

std::string texel_memory_caution(const TexelFields& fields, std::int64_t available_bytes) {
  const std::int64_t needed = texel_memory_lower_bound(fields);
  if (!near_memory_limit(needed, available_bytes)) return "";
  return "enrichment.texture_resolution " + std::to_string(fields.resolution) + ": the texel fields need at least " +
         memory_size_text(needed) + " of the " + memory_size_text(available_bytes) +
         " of memory available, and runs measured 1.3-4x that bound; the run may be killed for memory (a lower "
         "texture_resolution is safer)";
}

}  // namespace dgtex
