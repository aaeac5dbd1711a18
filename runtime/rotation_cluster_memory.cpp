#include "rotation_cluster_memory.h"

#include <string>

#include "dgtex/model_error.h"
#include "dgtex/texel_memory_estimate.h"
#include "multigrid_buffer.h"

namespace dgtex::detail {

void check_rotation_cluster_memory(std::int64_t rest_bytes, std::int64_t available_bytes, int block_texels,
                                   std::int64_t clusters) {
  if (available_bytes < 0 || rest_bytes <= available_bytes) return;
  throw ModelError("enrichment.rotation_cluster_texels = " + std::to_string(block_texels) + ": " +
                   std::to_string(clusters) + " rotation clusters would take " + memory_size_text(rest_bytes) +
                   " of rest sums, more than the " + memory_size_text(available_bytes) +
                   " of memory available; use larger blocks or 0 (a rotation per point, no rest sums)");
}

std::int64_t rotation_cluster_memory_available() {
  const std::int64_t available = available_memory_bytes();
  return available < 0 ? available : available + static_cast<std::int64_t>(cached_block_bytes());
}

}  // namespace dgtex::detail
