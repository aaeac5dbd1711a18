#pragma once
// Memory for the first steps of a run with cuts, faulted in before the steps start.
// Why: the first cut updates, projections and assemblies of a process touch tens of MB for
// the first time, and every fresh 4 KiB page costs the system a fault (~1.5 us on the
// 2-core VMs of the benchmarks): chad's first two steps faulted in 10.3k and 6.6k pages,
// 40 ms of peak step against 26 in a process that had run chad before (session 60,
// examples/bench_scenes_history.md). Reserved ahead, those pages are faulted in by the
// set-up instead, and the steps reuse them.
//
// What reserve_step_memory changes is process-wide, and lasts for the process:
// - glibc's malloc keeps what is freed (no trimming of the heap, blocks below 32 MiB from
//   the heap rather than from fresh mappings), and every thread that has not allocated yet
//   shares the main heap (its arenas limited to one), so the cut update that runs beside a
//   step on a thread of its own reuses the pages of the one before it. The process then
//   keeps its peak heap until it ends, as `dgtex run` and `dgtex bench` do anyway;
// - `bytes` of heap are faulted in now (2/3) and of the 2 MiB blocks of the Laplace
//   multigrid (1/3), or topped up to that where an earlier call reserved less.
// With another C library than glibc only the multigrid's part is reserved. Thread-safe;
// call it (or prepare_step_memory) before the threads that run the steps allocate, for
// them to share the reserved heap (SceneRunOptions::reserve_step_memory does so in the
// set-up of a SceneRun: the `dgtex` tool's `run` and `bench scenes`). Throws
// std::invalid_argument for more bytes than available_memory_bytes() (faulting them in
// would get the process killed rather than a std::bad_alloc), std::bad_alloc where the
// memory is not to be had.
#include <cstdint>

#include "dgtex/texel_memory_estimate.h"

namespace dgtex {

void reserve_step_memory(std::int64_t bytes);

// reserve_step_memory's malloc settings alone (the first item above), for a caller that
// reserves once it knows how much: called before any thread but the caller allocates, every
// thread shares the heap the reservation faults in later. A thread that allocated before
// them keeps a heap of its own, which no reservation reaches (SceneRun's OpenMP worker once
// it had traced cuts: fracture's time-0 update then faulted in 1.2k pages, the accordion's
// first step 2.9k; session 65). Thread-safe; settings already made stay.
void prepare_step_memory();

// What SceneRun reserves for a scene's texel fields: 6 times their lower bound
// (texel_memory_lower_bound; chad: 16 -> 96 MiB), at most 512 MiB and a quarter of the
// memory available (where known, >= 0).
std::int64_t step_memory_bytes(const TexelFields& fields, std::int64_t available_bytes);

}  // namespace dgtex
