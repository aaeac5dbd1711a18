#pragma once
// forall: the one parallel loop of dgtex kernels (below, forall_dynamic: its indices handed
// out as threads free up; forall_then: two in a row). Every kernel is written as a body over
// an index so the same code runs serially (the reference) or with OpenMP (and later on a
// device). Static scheduling keeps each index's work on a fixed thread per count, but
// kernels never rely on that: each index writes only its own outputs.
// Conventions of every dgtex::kernels header: arrays (structure of arrays) belong to the
// caller; *Batch / *View structs only point into them and must outlive the call; a kernel
// keeps nothing and has no global state, so calls on distinct outputs are thread-safe.
// Execution::parallel uses the OpenMP threads of the calling thread (less those busy beside
// it, threads_busy_beside.h), Execution::serial one; both give the same result (bitwise where
// documented).
#include <algorithm>
#include <atomic>
#include <cstdint>
#include <exception>

#include "dgtex/kernels/threads_busy_beside.h"

namespace dgtex::kernels {

enum class Execution { serial, parallel };

// While threads are busy beside the caller (threads_busy_beside.h), forall and
// forall_dynamic run their indices in slices of 1/rejoin_slices each, every slice on the team
// free at its start: a loop begun beside the side work takes the freed threads back at its
// next slice instead of finishing on the smaller team while a core idles. (The slinky left a
// core idle 13 % of the time, mostly beside loops begun during the cut update: the new
// basis's mass pass and rotation cluster sums.) Without side work: one region, as before.
constexpr std::int64_t rejoin_slices = 16;
template <class Loop>
void run_rejoining(std::int64_t n, Loop&& loop) {
  const std::int64_t slice = (n + rejoin_slices - 1) / rejoin_slices;
  for (std::int64_t begin = 0; begin < n;) {
    const int team = parallel_team_size();
    const std::int64_t end = team < omp_get_max_threads() && n - begin > slice ? begin + slice : n;
    loop(begin, end, team);
    begin = end;
  }
}

// An exception cannot leave an OpenMP region (std::terminate: chad out of memory in its
// quadrature pass ended in "terminate called after throwing an instance of
// 'std::bad_alloc'"). Inside one, work runs through run(): the first exception is kept, work
// started after it is skipped, and rethrow() passes it on once the region is over, as the
// serial loop would have thrown it. forall guards each thread's whole block of indices, not
// each index (a guard per index read a third slower in one sitting; bench_scenes_history.md).
class RegionFailure {
 public:
  template <class Work>
  void run(Work&& work) noexcept {
    if (failed_.load(std::memory_order_relaxed)) return;
    try {
      work();
    } catch (...) {
      bool first = false;
      if (failed_.compare_exchange_strong(first, true)) error_ = std::current_exception();
    }
  }
  void rethrow() const {
    if (error_) std::rethrow_exception(error_);
  }

 private:
  std::atomic<bool> failed_{false};
  std::exception_ptr error_;  // written once, by the thread that set failed_, read after the region
};

// Indices [begin, end) in contiguous blocks, one a thread, as schedule(static) splits them.
template <class Body>
void run_static_blocks(std::int64_t begin, std::int64_t end, Body& body, RegionFailure& failure) {
  const std::int64_t n = end - begin, threads = omp_get_num_threads(), t = omp_get_thread_num();
  const std::int64_t size = n / threads, extra = n % threads;
  const std::int64_t first = begin + t * size + std::min(t, extra), last = first + size + (t < extra ? 1 : 0);
  failure.run([&] {
    for (std::int64_t i = first; i < last; ++i) body(i);
  });
}

template <class Body>
void forall(std::int64_t n, Body&& body, Execution execution = Execution::parallel) {
  if (execution == Execution::parallel) {
    RegionFailure failure;
    run_rejoining(n, [&](std::int64_t begin, std::int64_t end, int team) {
#pragma omp parallel num_threads(team)
      run_static_blocks(begin, end, body, failure);
      failure.rethrow();
    });
  } else {
    for (std::int64_t i = 0; i < n; ++i) body(i);
  }
}

// forall with the indices handed out one at a time as threads free up: for a few items of
// very different cost (rotation clusters, stiffness chunks, enriched edges). Each index must
// write only its own outputs, so the result is that of forall.
template <class Body>
void forall_dynamic(std::int64_t n, Body&& body, Execution execution = Execution::parallel) {
  if (execution == Execution::parallel) {
    RegionFailure failure;
    run_rejoining(n, [&](std::int64_t begin, std::int64_t end, int team) {
#pragma omp parallel for schedule(dynamic, 1) num_threads(team)
      for (std::int64_t i = begin; i < end; ++i) failure.run([&] { body(i); });
      failure.rethrow();
    });
  } else {
    for (std::int64_t i = 0; i < n; ++i) body(i);
  }
}

// forall(n1, first), then forall(n2, second), with every first(i) done before any second(i):
// in one parallel region, the two loops separated by a barrier instead of two regions. For
// the multigrid's lagged sweeps and two-pass setup kernels: Laplace T = 256 solves ~3 %
// faster (2-core machine, OMP_WAIT_POLICY=active, five alternating runs).
template <class First, class Second>
void forall_then(std::int64_t n1, First&& first, std::int64_t n2, Second&& second,
                 Execution execution = Execution::parallel) {
  if (execution == Execution::parallel && parallel_team_size() < omp_get_max_threads()) {
    // Beside busy side work: two loops that can each take threads back (run_rejoining).
    forall(n1, first, execution);
    forall(n2, second, execution);
  } else if (execution == Execution::parallel) {
    RegionFailure failure;
#pragma omp parallel num_threads(parallel_team_size())
    {
      run_static_blocks(0, n1, first, failure);
#pragma omp barrier
      run_static_blocks(0, n2, second, failure);
    }
    failure.rethrow();
  } else {
    for (std::int64_t i = 0; i < n1; ++i) first(i);
    for (std::int64_t i = 0; i < n2; ++i) second(i);
  }
}

}  // namespace dgtex::kernels
