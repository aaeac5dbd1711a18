#pragma once
// Internal: restores, when it goes out of scope, the OpenMP thread count that the calling
// thread had when the guard was made. omp_set_num_threads outlives the function that calls
// it, so a function that times work at several thread counts (the `bench` families, the
// shell benchmark) would otherwise leave the caller's program at the last count it tried.
#include <omp.h>

namespace dgtex::detail {

class ThreadCountGuard {
 public:
  ThreadCountGuard() : saved_(omp_get_max_threads()) {}
  // Sets the count to `threads` until the guard goes out of scope.
  explicit ThreadCountGuard(int threads) : ThreadCountGuard() { omp_set_num_threads(threads); }
  ~ThreadCountGuard() { omp_set_num_threads(saved_); }
  ThreadCountGuard(const ThreadCountGuard&) = delete;
  ThreadCountGuard& operator=(const ThreadCountGuard&) = delete;

 private:
  int saved_;
};

}  // namespace dgtex::detail
