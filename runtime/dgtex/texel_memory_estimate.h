#pragma once
// Will a scene's enrichment fit in memory? Its texel fields grow with T^2 times the elements
// around the cuts and creases (per cut segment and per crease, a T x T field on every
// element of its region Omega_i): fracture.json's ~280 segment regions take 1.9 GB at
// T = 256 and 8.9 GB at 512, and at T = 1024 the process outgrew a 23 GB machine and the
// system killed it, minutes in and without a word. SceneRun checks a lower bound of that
// memory before the first field is allocated and refuses such a scene with one line (a
// SceneError naming enrichment.texture_resolution, the bound, the memory available and
// the largest T that could fit).
//
// The bound, per texel of every field's region (T^2 a quad8 tile, T(T+1)/2 active texels a
// tri6 one), from the peak resident memory of the example scenes with their cuts whole from
// the start (set-up and one step, T = 256-4096, 2-core machine; README "enrichment"):
//  - cuts with multigrid Laplace solves: 84-226 bytes, falling with T toward ~85 (spiral6
//    at 4096: 8.5 GB); bound kFieldBytesPerTexel;
//  - cuts on tri6 elements, and cuts whose solves run on the texel graph: the algebraic
//    multigrid's hierarchy (cells split sheared), 203-257 bytes at T = 256-128 (fracture,
//    session 43); lattice patches of the tile multigrid (cells split square), 192-272 bytes
//    at T = 512-128 (fracture, session 45); enrichment.solver "cholmod": CHOLMOD's factor,
//    187-678 bytes: bound kGraphSolveBytesPerTexel;
//  - creases (a fast-marching distance, no solve): 81-82 bytes (a crease over 8 of 64
//    quad8 elements, T = 512 and 1024); bound kFieldBytesPerTexel.
// A scene that passes may still need several times the bound (chad's cut on tri6
// elements, one 8-element region: 4x). Material textures have their own check
// (check_material_texture_memory, material_texture.h). Pure functions
// but available_memory_bytes (reads /proc, the cgroup's limit and RLIMIT_AS).
#include <cstdint>
#include <string>

#include "dgtex/mesh.h"

namespace dgtex {

inline constexpr std::int64_t kFieldBytesPerTexel = 64;
inline constexpr std::int64_t kGraphSolveBytesPerTexel = 160;

// Enrichment fields of one kind (cut segments, or creases) and their regions.
struct TexelFootprint {
  int fields = 0;                    // functions: cut segments, or creases
  std::int64_t region_elements = 0;  // sum over fields of |Omega_i|: a T x T tile each
};

// What a scene's enrichment holds at texture resolution T.
struct TexelFields {
  ElementType type = ElementType::quad8;
  int resolution = 0;          // T
  bool graph_solves = false;  // the cuts' Laplace solves run on the texel graph (tri6, or CHOLMOD)
  TexelFootprint cuts, creases;
};

// Lower bound of the peak memory of the fields, in bytes.
std::int64_t texel_memory_lower_bound(const TexelFields& fields);

// Memory this process may still take, in bytes: MemAvailable + SwapFree of /proc/meminfo,
// capped by the cgroup's limit less its usage (cgroup v2 memory.max, v1
// memory.limit_in_bytes) where one is set, by the address space left under `ulimit -v`
// (RLIMIT_AS less the process's virtual size) where that is set, and by the environment's
// DGTEX_MEMORY_LIMIT_MB (MiB; to share a machine, or to try a scene's limits) where that is
// set; -1 when none of /proc/meminfo, `ulimit -v` and DGTEX_MEMORY_LIMIT_MB gives a figure.
// Throws std::invalid_argument naming DGTEX_MEMORY_LIMIT_MB when it is set but not a whole
// number >= 1.
std::int64_t available_memory_bytes();

// A memory size as every memory refusal and caution writes it, in the binary units of
// DGTEX_MEMORY_LIMIT_MB: whole MiB below 1 GiB ("645 MiB"), else GiB to one decimal
// ("355.1 GiB").
std::string memory_size_text(std::int64_t bytes);

// Throws SceneError(source_name, "enrichment.texture_resolution", ...) when the lower
// bound exceeds available_bytes, naming both, the fields and the largest power of two
// T >= 8 whose bound fits (or that none does). available_bytes < 0: no check.
void check_texel_memory(const TexelFields& fields, std::int64_t available_bytes, const std::string& source_name);

// Whether a lower bound of `needed` bytes calls for a caution rather than a refusal or
// nothing: above half the memory available and within all of it (available_bytes < 0:
// never). The texel fields' and the model's cautions share it.
bool near_memory_limit(std::int64_t needed, std::int64_t available_bytes);

// A caution for a scene that passes the check but comes near the limit: runs measured
// 1.3-4x the bound, so above half the memory available it may still be killed. One
// sentence naming the bound, the memory and the remedy, for `dgtex run` to print before its
// set-up, when the bound lies between half the memory available and all of it; else ""
// (also with available_bytes < 0).
std::string texel_memory_caution(const TexelFields& fields, std::int64_t available_bytes);

}  // namespace dgtex
