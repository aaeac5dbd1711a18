// Parallel loops of a thread with work running beside it (dgtex/kernels/threads_busy_beside.h):
// forall, forall_dynamic, forall_then and run_side_by_side leave out the threads that work
// holds, take them back once the count drops (forall, forall_dynamic and forall_then within
// the loop, at their next slice), and a scope restores the thread's previous setting.
// SceneRun's overlapped cut updates, which set the count, keep the plain bits
// (test_scene_run_overlap).
#include <gtest/gtest.h>

#include <omp.h>

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

#include "dgtex/kernels/forall.h"
#include "dgtex/side_by_side.h"
#include "thread_count_support.h"

using namespace dgtex;

namespace {

// The largest team any iteration of each loop kind ran in.
struct Teams {
  int forall = 0, dynamic = 0, then = 0;
};

Teams loop_teams() {
  constexpr std::int64_t n = 64;
  std::vector<int> forall_team(n), dynamic_team(n), then_team(2 * n);
  kernels::forall(n, [&](std::int64_t i) { forall_team[i] = omp_get_num_threads(); });
  kernels::forall_dynamic(n, [&](std::int64_t i) { dynamic_team[i] = omp_get_num_threads(); });
  kernels::forall_then(
      n, [&](std::int64_t i) { then_team[i] = omp_get_num_threads(); }, n,
      [&](std::int64_t i) { then_team[n + i] = omp_get_num_threads(); });
  Teams teams;
  for (int t : forall_team) teams.forall = std::max(teams.forall, t);
  for (int t : dynamic_team) teams.dynamic = std::max(teams.dynamic, t);
  for (int t : then_team) teams.then = std::max(teams.then, t);
  return teams;
}

class ThreadsBusyBeside : public ::testing::Test {
 protected:
  const test::ThreadCountGuard three_threads_{3};
};

}  // namespace

TEST_F(ThreadsBusyBeside, LoopsLeaveOutTheThreadsBusyBesideTheCaller) {
  ASSERT_EQ(kernels::threads_busy_beside, nullptr);
  EXPECT_EQ(kernels::parallel_team_size(), 3);
  EXPECT_EQ(loop_teams().forall, 3);
  std::atomic<int> busy{1};
  {
    const kernels::ScopedThreadsBusyBeside beside(&busy);
    EXPECT_EQ(kernels::parallel_team_size(), 2);
    const Teams teams = loop_teams();
    EXPECT_EQ(teams.forall, 2);
    EXPECT_EQ(teams.dynamic, 2);
    EXPECT_EQ(teams.then, 2);
    busy = 5;  // more than the caller has: it keeps one thread
    EXPECT_EQ(kernels::parallel_team_size(), 1);
    EXPECT_EQ(loop_teams().forall, 1);
    busy = 0;  // the side work is done: the whole team again
    const Teams again = loop_teams();
    EXPECT_EQ(again.forall, 3);
    EXPECT_EQ(again.dynamic, 3);
    EXPECT_EQ(again.then, 3);
  }
  EXPECT_EQ(kernels::threads_busy_beside, nullptr);
}

TEST_F(ThreadsBusyBeside, ScopesNestAndStayWithTheirThread) {
  std::atomic<int> outer{1}, inner{2};
  const kernels::ScopedThreadsBusyBeside a(&outer);
  {
    const kernels::ScopedThreadsBusyBeside b(&inner);
    EXPECT_EQ(kernels::parallel_team_size(), 1);
    // Another thread sees nothing of this thread's setting.
    int other = 0;
    std::thread([&] {
      omp_set_num_threads(3);
      other = kernels::parallel_team_size();
    }).join();
    EXPECT_EQ(other, 3);
  }
  EXPECT_EQ(kernels::threads_busy_beside, &outer);
  EXPECT_EQ(kernels::parallel_team_size(), 2);
}

TEST_F(ThreadsBusyBeside, SideWorkThatFinishesHandsItsThreadBack) {
  // As in SceneRun: the count is 1 while a thread works beside the loops, and that thread
  // lowers it as it finishes.
  std::atomic<int> busy{1};
  const kernels::ScopedThreadsBusyBeside beside(&busy);
  std::thread side([&] { busy.store(0, std::memory_order_release); });
  side.join();
  EXPECT_EQ(loop_teams().forall, 3);
}

// A loop begun beside side work that finishes while it runs: its later slices run on the
// whole team, every index exactly once (forall_then: its first loop).
TEST_F(ThreadsBusyBeside, LoopsTakeTheThreadsBackWhileTheyRun) {
  constexpr std::int64_t n = 10 * kernels::rejoin_slices;
  for (const int kind : {0, 1, 2}) {
    SCOPED_TRACE(kind == 0 ? "forall" : kind == 1 ? "forall_dynamic" : "forall_then");
    std::atomic<int> busy{2};
    std::vector<int> team(n, 0), visits(n, 0);
    const auto body = [&](std::int64_t i) {
      team[i] = omp_get_num_threads();
      ++visits[i];  // each index is written by one thread only
      if (i == 3) busy.store(0, std::memory_order_release);  // the side work ends in the first slice
    };
    {
      const kernels::ScopedThreadsBusyBeside beside(&busy);
      if (kind == 0) kernels::forall(n, body);
      if (kind == 1) kernels::forall_dynamic(n, body);
      if (kind == 2) kernels::forall_then(n, body, 0, [](std::int64_t) {});
    }
    for (std::int64_t i = 0; i < n; ++i) ASSERT_EQ(visits[i], 1) << "index " << i;
    EXPECT_EQ(team.front(), 1);  // began beside the side work: one thread of three
    EXPECT_EQ(team.back(), 3);   // the later slices: the whole team
    EXPECT_EQ(*std::max_element(team.begin(), team.begin() + n / kernels::rejoin_slices), 1);
  }
}

TEST_F(ThreadsBusyBeside, SideBySideRunsInTurnWhenOnlyOneThreadIsFree) {
  const test::ThreadCountGuard set_threads(2);
  const std::thread::id caller = std::this_thread::get_id();
  std::thread::id first_ran_on, second_ran_on;
  std::atomic<int> busy{1};
  {
    const kernels::ScopedThreadsBusyBeside beside(&busy);
    run_side_by_side([&] { first_ran_on = std::this_thread::get_id(); },
                     [&] { second_ran_on = std::this_thread::get_id(); });
  }
  EXPECT_EQ(first_ran_on, caller);
  EXPECT_EQ(second_ran_on, caller);
  // Nothing busy: the second task runs on a thread of its own.
  run_side_by_side([&] { first_ran_on = std::this_thread::get_id(); },
                   [&] { second_ran_on = std::this_thread::get_id(); });
  EXPECT_NE(first_ran_on, second_ran_on);
}
