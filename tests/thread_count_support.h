#pragma once
// OpenMP's thread count in tests that run a kernel at several counts. omp_set_num_threads
// outlives the test that calls it: a test that sets it holds a detail::ThreadCountGuard
// (runtime/thread_count_guard.h), so that the later tests of the same executable run at the
// machine's count (OMP_NUM_THREADS or the cores), not at whatever count was set last.
#include <omp.h>

#include "thread_count_guard.h"  // internal (runtime/)

namespace dgtex::test {

using detail::ThreadCountGuard;

// call() with the thread count set to `threads`, restored after.
template <class Call>
auto with_threads(int threads, Call&& call) {
  const ThreadCountGuard set_threads(threads);
  return call();
}

}  // namespace dgtex::test
