#pragma once
// How many OpenMP threads SceneRun's overlapped cut update gets (the step's parallel loops
// take the rest). On two threads it is always one each. On more, the update of a T = 256
// cut scene became the step's bottleneck: on a 16-core Xeon (session 49, `dgtex bench
// scenes --threads 16`) chad's update took 16-22 ms a step on its one thread while the
// step's own work took 6-9 on the other fifteen. Its multigrid gains from a few threads, not
// from many (chad's T = 256 update: 42.5 ms on 1 thread, 29 on 2, 27 on 4, 28 on 8), and a
// small update (spiral1's) gets slower with a second thread. So the team grows by one while
// the update takes clearly longer than the step's own work beside it, keeps a thread only if
// it made the update at least 10 % faster (else it is given back and the team never grows
// past it again), and shrinks while the update takes much less than the step's own work.
// Times are smoothed, and a team size is judged after a few steps at it: steps with and
// without a basis change alternate. (Balancing the two times alone, a first version gave
// chad 14 of 16 threads, and spiral1 9-10: chad 57-59 -> 70-79 steps/s, but spiral1 140-153
// -> 118-119.) The thread counts change no result (every kernel gives the same bits on any
// number of threads), only when the step ends.
#include <algorithm>
#include <vector>

namespace dgtex::detail {

class CutUpdateTeam {
 public:
  // fixed > 0: always that many threads (at most the step's threads less one); 0: balanced.
  explicit CutUpdateTeam(int fixed = 0) : fixed_(fixed > 0), team_(fixed > 0 ? fixed : 1) {}

  // The team for an update beside a step of `threads` OpenMP threads: 1 to threads - 1.
  int size(int threads) const { return std::clamp(team_, 1, largest(threads)); }

  // One overlapped step: the update's wall time with the team size(threads) gave it, and
  // that of the step's own work beside it.
  void record(int threads, double update_ms, double beside_ms) {
    if (fixed_ || !(beside_ms > 0)) return;
    const int team = size(threads), most = largest(threads);
    ratio_ = ratio_ > 0 ? smooth(ratio_, update_ms / beside_ms) : update_ms / beside_ms;
    if (static_cast<int>(seen_.size()) <= team) seen_.resize(team + 1);
    Seen& at = seen_[team];
    at.ms = at.count > 0 ? smooth(at.ms, update_ms) : update_ms;
    team_ = team;
    if (++at.count < kStepsToJudge) return;
    if (team > 1 && !(at.ms < 0.9 * seen_[team - 1].ms)) ceiling_ = team - 1;  // its last thread did not help
    const int top = std::min(most, ceiling_);
    if (team > top) team_ = top;
    else if (ratio_ > 1.1 && team < top) team_ = team + 1;  // the step waits for the update
    else if (ratio_ < 0.6 && team > 1) team_ = team - 1;    // the update waits for the step
  }

 private:
  static constexpr double kWeight = 0.25;  // of the newest step in the smoothed times
  static constexpr int kStepsToJudge = 3;  // steps at a team size before it is judged
  static double smooth(double old, double newest) { return (1 - kWeight) * old + kWeight * newest; }
  static int largest(int threads) { return std::max(1, threads - 1); }  // the step keeps one
  struct Seen {
    double ms = 0;  // smoothed update time with this team size
    int count = 0;  // steps it ran with it
  };
  bool fixed_;
  int team_;
  int ceiling_ = 1 << 30;  // the team never grows past it: the next thread did not help
  double ratio_ = 0;       // smoothed update / beside time (0: none yet)
  std::vector<Seen> seen_;  // per team size
};

}  // namespace dgtex::detail
