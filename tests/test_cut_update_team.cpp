// The overlapped cut update's team (runtime/cut_update_team.h): one thread on two; on more,
// a thread more while the update takes clearly longer than the step's own work beside it,
// kept only if it made the update at least 10 % faster; one fewer while the update takes
// much less; never below 1 nor above the step's threads less one; a fixed team stays fixed.
#include <gtest/gtest.h>

#include <algorithm>

#include "cut_update_team.h"  // internal (runtime/)

using dgtex::detail::CutUpdateTeam;

TEST(CutUpdateTeam, TwoThreadsAlwaysGiveTheUpdateOne) {
  CutUpdateTeam team;
  for (int step = 0; step < 10; ++step) team.record(2, 30.0, 10.0);
  EXPECT_EQ(team.size(2), 1);
  EXPECT_EQ(team.size(1), 1);  // one thread: never 0
}

TEST(CutUpdateTeam, ASlowUpdateGainsThreadsWhileTheyHelp) {
  // An update that scales like chad's multigrid: 16.5 ms on 1 thread, then 11.5, 10, 9.6,
  // 9.4 ... (from 4 threads on less than 10 % a thread), beside 6 ms of the step's own work.
  const double update_ms[] = {0, 16.5, 11.5, 10.0, 9.6, 9.4, 9.3, 9.2};
  CutUpdateTeam team;
  for (int step = 0; step < 40; ++step) {
    const int k = team.size(16);
    ASSERT_LE(k, 7);
    team.record(16, update_ms[k], 6.0);
  }
  // The 2nd and 3rd threads helped (30 %, 13 %), the 4th did not (4 %): given back for good.
  EXPECT_EQ(team.size(16), 3);
  EXPECT_EQ(team.size(3), 2);  // fewer threads now: clamped to all but one
}

TEST(CutUpdateTeam, AnUpdateThatMoreThreadsDoNotSpeedUpKeepsOne) {
  // spiral1-like: the update gets slower with a second thread, which is tried and given back.
  CutUpdateTeam team;
  int largest = 1;
  for (int step = 0; step < 40; ++step) {
    largest = std::max(largest, team.size(16));
    team.record(16, team.size(16) == 1 ? 5.0 : 5.5, 3.0);
  }
  EXPECT_EQ(largest, 2);
  EXPECT_EQ(team.size(16), 1);
}

TEST(CutUpdateTeam, AnUpdateQuickerThanTheStepGivesItsThreadsBack) {
  CutUpdateTeam team;
  const double update_ms[] = {0, 16.0, 10.0, 7.0, 5.0};  // every thread helps
  for (int step = 0; step < 30; ++step) team.record(16, update_ms[std::min(team.size(16), 4)], 4.0);
  ASSERT_GE(team.size(16), 3);
  // The cut's hard part is over: the update takes a tenth of the step's own work.
  for (int step = 0; step < 40; ++step) team.record(16, 0.5, 5.0);
  EXPECT_EQ(team.size(16), 1);
}

TEST(CutUpdateTeam, SmoothedTimesIgnoreOneSlowStepAmongQuickOnes) {
  // Steps with and without a basis change alternate: a single slow update among quick ones
  // (ratio 0.8 on average) does not grow the team.
  CutUpdateTeam team;
  for (int step = 0; step < 30; ++step) team.record(16, step % 5 == 4 ? 12.0 : 5.0, 8.0);
  EXPECT_EQ(team.size(16), 1);
}

TEST(CutUpdateTeam, AFixedTeamStaysFixed) {
  CutUpdateTeam team(3);
  for (int step = 0; step < 10; ++step) team.record(16, 100.0, 1.0);
  EXPECT_EQ(team.size(16), 3);
  EXPECT_EQ(team.size(2), 1);  // clamped to the step's threads less one
}
