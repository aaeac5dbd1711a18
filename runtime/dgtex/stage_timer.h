#pragma once
// Per-stage wall-clock statistics (mean and max over calls), in milliseconds.
// Value types; ScopedStage keeps a reference to its StageTimings entry (which must outlive
// it). Not thread-safe: time stages from one thread. Times in milliseconds.
#include <chrono>
#include <ctime>
#include <map>
#include <string>

namespace dgtex {

// Milliseconds of wall clock since `start`.
inline double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

// CPU milliseconds this process has used (all threads): robust against other processes
// taking the cores, unlike wall-clock times.
inline double process_cpu_ms() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec * 1e3 + t.tv_nsec * 1e-6;
}

struct StageStatistics {
  double total_ms = 0;
  double max_ms = 0;
  long count = 0;
  void add(double ms) {
    total_ms += ms;
    max_ms = ms > max_ms ? ms : max_ms;
    ++count;
  }
  double mean_ms() const { return count ? total_ms / count : 0.0; }
};

using StageTimings = std::map<std::string, StageStatistics>;

// Adds the time from construction to destruction (plus earlier_ms, time of this stage
// spent before, e.g. waiting in a concurrent section) to one stage.
class ScopedStage {
 public:
  ScopedStage(StageTimings& timings, const std::string& stage, double earlier_ms = 0)
      : stats_(timings[stage]), start_(std::chrono::steady_clock::now()), earlier_ms_(earlier_ms) {}
  ~ScopedStage() {
    stats_.add(earlier_ms_ + std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count());
  }
  // Time within the scope that is not the stage's (SceneRun's set-up: reserving memory).
  void exclude(double ms) { earlier_ms_ -= ms; }
  ScopedStage(const ScopedStage&) = delete;
  ScopedStage& operator=(const ScopedStage&) = delete;

 private:
  StageStatistics& stats_;
  std::chrono::steady_clock::time_point start_;
  double earlier_ms_;
};

}  // namespace dgtex
