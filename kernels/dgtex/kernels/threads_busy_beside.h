#pragma once
// The OpenMP team of a parallel loop whose calling thread has work of its own running beside
// it on another thread (SceneRun's overlapped cut update). Such a thread points
// threads_busy_beside at a count of the threads that work holds, and the side work lowers the
// count as it finishes; meanwhile the caller's parallel loops leave that many threads out.
// On two cores a team of two beside a busy third thread time-slices, and each of its barriers
// waits for whichever member is not running; a team of one runs at full speed and takes the
// second core back for the loops after the side work is done. Only team sizes change, and the
// kernels give the same bits on any number of threads.
#include <atomic>

#include <omp.h>

namespace dgtex::kernels {

// Per calling thread; null: nothing runs beside it.
inline thread_local const std::atomic<int>* threads_busy_beside = nullptr;

// The calling thread's OpenMP threads less those busy beside it, at least 1.
inline int parallel_team_size() {
  const int threads = omp_get_max_threads();
  const int busy = threads_busy_beside ? threads_busy_beside->load(std::memory_order_acquire) : 0;
  return threads > busy ? threads - busy : 1;
}

// Points the calling thread's threads_busy_beside at `busy` for this object's lifetime.
class ScopedThreadsBusyBeside {
 public:
  explicit ScopedThreadsBusyBeside(const std::atomic<int>* busy) : previous_(threads_busy_beside) {
    threads_busy_beside = busy;
  }
  ~ScopedThreadsBusyBeside() { threads_busy_beside = previous_; }
  ScopedThreadsBusyBeside(const ScopedThreadsBusyBeside&) = delete;
  ScopedThreadsBusyBeside& operator=(const ScopedThreadsBusyBeside&) = delete;

 private:
  const std::atomic<int>* previous_;
};

}  // namespace dgtex::kernels
