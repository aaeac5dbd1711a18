#pragma once
// Runs two tasks at once on two OpenMP threads, or one after the other when only one
// thread is available. Parallel loops inside either task run serially (nested regions stay
// inactive: CHOLMOD's own OpenMP loops, made active, multiplied the CPU time of a
// factorisation tenfold). For a serial task beside one that would use the team, e.g. a
// CHOLMOD factorisation F (~30 ms, cylinder scene) beside the assembly A (~17 ms on one
// thread, ~9 on two): max(F, A) instead of F + A / T on T threads, a gain while
// F > A (1 - 1/T). Both tasks must be independent (no shared writes); the results do not
// depend on how they overlap. The first exception thrown by either task (first's, if both
// throw) is rethrown after both have finished. Threads busy beside the caller already
// (threads_busy_beside.h) count as unavailable.
#include <chrono>
#include <exception>

#include <omp.h>

#include "dgtex/kernels/threads_busy_beside.h"

namespace dgtex {

struct SideBySideTimes {
  double total_ms = 0;   // wall time of the whole call
  double second_ms = 0;  // wall time of `second` alone
};

template <class First, class Second>
SideBySideTimes run_side_by_side(First&& first, Second&& second) {
  using Clock = std::chrono::steady_clock;
  const auto ms_from = [](Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  };
  SideBySideTimes times;
  const Clock::time_point start = Clock::now();
  std::exception_ptr errors[2];
  if (kernels::parallel_team_size() < 2) {
    try {
      first();
    } catch (...) {
      errors[0] = std::current_exception();
    }
    const Clock::time_point second_start = Clock::now();
    try {
      second();
    } catch (...) {
      errors[1] = std::current_exception();
    }
    times.second_ms = ms_from(second_start);
  } else {
#pragma omp parallel num_threads(2)
    {
      const int task = omp_get_thread_num();
      omp_set_num_threads(1);  // nested loops serial even where nesting is enabled
      try {
        if (task == 0) {
          first();
        } else {
          const Clock::time_point second_start = Clock::now();
          second();
          times.second_ms = ms_from(second_start);
        }
      } catch (...) {
        errors[task] = std::current_exception();
      }
    }
  }
  times.total_ms = ms_from(start);
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
  return times;
}

}  // namespace dgtex
