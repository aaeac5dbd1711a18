#pragma once
// Internal: the memory guard of the rotation clusters' rest sums (shell_model.cpp). Their
// size grows with the square of an element's functions over the number of clusters (the
// accordion at B = 8: 645 MB), so a small block setting can ask for more than the machine
// has. The guard refuses it with the setting to change instead of letting the system kill
// the process; a fixed limit (4 GiB until session 41) refused big machines what they could
// hold and let small ones be killed.
#include <cstdint>

namespace dgtex::detail {

// Throws ModelError naming enrichment.rotation_cluster_texels (block_texels), the cluster
// count, the memory the rest sums need and that available (memory_size_text), when
// rest_bytes exceed available_bytes: memory the process may still take
// (available_memory_bytes()) plus the released blocks it keeps for reuse
// (cached_block_bytes()). available_bytes < 0: no check.
void check_rotation_cluster_memory(std::int64_t rest_bytes, std::int64_t available_bytes, int block_texels,
                                   std::int64_t clusters);

// What check_rotation_cluster_memory compares against on this machine now.
std::int64_t rotation_cluster_memory_available();

}  // namespace dgtex::detail
