// run_side_by_side (dgtex/side_by_side.h): both tasks run, on distinct threads when two are
// available, loops inside them stay serial, and an exception from either reaches the caller
// after both have finished.
#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <stdexcept>

#include "dgtex/side_by_side.h"
#include "thread_count_support.h"

using namespace dgtex;

TEST(SideBySide, RunsBothTasksOnDistinctThreadsWithSerialInnerLoops) {
  for (int threads : {1, 2, 4}) {
    const test::ThreadCountGuard set_threads(threads);
    int first_thread = -1, second_thread = -1, first_inner = 0, second_inner = 0;
    const SideBySideTimes t = run_side_by_side(
        [&] {
          first_thread = omp_get_thread_num();
#pragma omp parallel
          first_inner = omp_get_num_threads();
        },
        [&] {
          second_thread = omp_get_thread_num();
#pragma omp parallel
          second_inner = omp_get_num_threads();
        });
    EXPECT_EQ(first_inner, 1) << threads;
    EXPECT_EQ(second_inner, 1) << threads;
    if (threads >= 2) {
      EXPECT_NE(first_thread, second_thread) << threads;
    }
    EXPECT_GE(t.total_ms, t.second_ms);
    EXPECT_EQ(omp_get_max_threads(), threads);  // the caller's team size is unchanged
  }
}

TEST(SideBySide, RethrowsAfterBothTasksFinished) {
  for (int threads : {1, 2}) {
    const test::ThreadCountGuard set_threads(threads);
    std::atomic<bool> second_done{false};
    EXPECT_THROW(run_side_by_side([] { throw std::runtime_error("first failed"); }, [&] { second_done = true; }),
                 std::runtime_error);
    EXPECT_TRUE(second_done) << threads;
    std::atomic<bool> first_done{false};
    EXPECT_THROW(run_side_by_side([&] { first_done = true; }, [] { throw std::invalid_argument("second failed"); }),
                 std::invalid_argument);
    EXPECT_TRUE(first_done) << threads;
  }
}
