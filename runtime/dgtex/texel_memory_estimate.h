#pragma once
// Will a scene's cut enrichment fit in memory? Its texel fields grow with T^2 times the
// elements around the cuts (one T x T field per segment and element of its region
// Omega_i): fracture.json's 280 segment regions take 1.9 GB at T = 256 and 8.9 GB at 512,
// and at T = 1024 the process outgrew a 23 GB machine and the system killed it, minutes
// in and without a word. SceneRun checks a lower bound of that memory before the first
// update allocates a tile and refuses such a scene with one line (a SceneError naming
// enrichment.texture_resolution, the estimate, the memory available and the largest T
// that fits).
//
// The bound, per texel of every segment's region (T^2 a quad8 tile, T(T+1)/2 active
// texels a tri6 one), from peak resident memory measured over the example scenes with
// their cuts whole from the start (set-up and one step, T = 256-4096, 2-core machine;
// README "enrichment"): with multigrid solves 84-226 bytes (falling with T toward ~85:
// spiral6 at 4096), bounded below by kMultigridBytesPerTexel; where a region's Laplace
// solve is direct (tri6 elements, or enrichment.solver "cholmod": CHOLMOD's factor)
// 187-678 bytes, bounded below by kDirectSolveBytesPerTexel. A scene that passes may still
// need several times the bound (chad on tri6 elements, one 8-element region: 4x).
// Creases and material textures are not counted. Pure functions but
// available_memory_bytes (reads /proc and the cgroup's limit).
#include <cstdint>
#include <string>

#include "dgtex/cut_manager.h"
#include "dgtex/mesh.h"

namespace dgtex {

inline constexpr std::int64_t kMultigridBytesPerTexel = 64;
inline constexpr std::int64_t kDirectSolveBytesPerTexel = 160;

// Lower bound of the peak memory the cuts' enrichment takes, in bytes, at the footprint's
// resolution. direct_solves: the regions' Laplace solves go to CHOLMOD (tri6 elements
// always; quad8 with enrichment.solver "cholmod").
std::int64_t texel_memory_lower_bound(const CutTexelFootprint& footprint, ElementType type, bool direct_solves);

// Memory this process may still take, in bytes: MemAvailable + SwapFree of /proc/meminfo,
// capped by the cgroup's limit less its usage (cgroup v2 memory.max, v1
// memory.limit_in_bytes) where one is set; -1 when /proc/meminfo cannot be read.
std::int64_t available_memory_bytes();

// Throws SceneError(source_name, "enrichment.texture_resolution", ...) when the lower
// bound exceeds available_bytes, naming both, the cuts' footprint and the largest power of
// two T >= 8 whose bound fits (or that none does). available_bytes < 0: no check.
void check_texel_memory(const CutTexelFootprint& footprint, ElementType type, bool direct_solves,
                        std::int64_t available_bytes, const std::string& source_name);

}  // namespace dgtex
