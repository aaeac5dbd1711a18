// The machine line and speed probe of the benchmark reports (dgtex/benchmark_machine.h).
#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <omp.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "dgtex/benchmark_machine.h"
#include "thread_count_support.h"

using namespace dgtex;

using test::with_threads;

TEST(BenchmarkMachine, DescriptionNamesTheCoresAndThreads) {
  const std::string one = with_threads(1, describe_machine);
  const std::string three = with_threads(3, describe_machine);
  EXPECT_NE(one.find(" cores, 1 thread"), std::string::npos) << one;
  EXPECT_NE(three.find(" cores, 3 threads"), std::string::npos) << three;
}

// The probe's figure is the time of work done within the call: more than zero (2^25
// multiply-adds are far above the clock's resolution) and at most the call's own wall time,
// whatever the machine's speed (bounds in ms failed on a loaded machine).
double call_ms(const std::function<double()>& probe, double& probe_ms) {
  const auto start = std::chrono::steady_clock::now();
  probe_ms = probe();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

TEST(BenchmarkMachine, ProbeTimesItsWorkloadAndRejectsNoRuns) {
  double ms = 0;
  const double call = call_ms([] { return machine_probe_ms(1); }, ms);
  EXPECT_TRUE(std::isfinite(ms));
  EXPECT_GT(ms, 0);
  EXPECT_LE(ms, call);
  EXPECT_THROW(machine_probe_ms(0), std::invalid_argument);
}

TEST(BenchmarkMachine, AllThreadsProbeTimesTheWorkloadOnEveryThreadAndRejectsBadArguments) {
  for (int threads : {1, 2}) {
    double ms = 0;
    const double call = call_ms([&] { return machine_probe_all_threads_ms(threads, 1); }, ms);
    EXPECT_TRUE(std::isfinite(ms)) << threads;
    EXPECT_GT(ms, 0) << threads;
    EXPECT_LE(ms, call) << threads;
  }
  EXPECT_THROW(machine_probe_all_threads_ms(0), std::invalid_argument);
  EXPECT_THROW(machine_probe_all_threads_ms(2, 0), std::invalid_argument);
}

TEST(BenchmarkMachine, ChartHeadingNamesTheMachineAndBothProbes) {
  const std::string one = with_threads(1, describe_machine_and_probe);
  const std::string two = with_threads(2, describe_machine_and_probe);
  const std::string machine_with_two = with_threads(2, describe_machine);
  // The description, then the one-core probe; with threads, the probe on all of them too.
  EXPECT_NE(one.find(", one-core probe "), std::string::npos) << one;
  EXPECT_EQ(one.substr(one.size() - 3), " ms") << one;
  EXPECT_EQ(one.find("at once"), std::string::npos) << one;
  EXPECT_EQ(two.rfind(machine_with_two + ", one-core probe ", 0), 0u) << two;
  EXPECT_NE(two.find(" ms (2 threads at once: "), std::string::npos) << two;
  EXPECT_EQ(two.substr(two.size() - 4), " ms)") << two;
}

TEST(BenchmarkMachine, SharedCoresWarningOnlyWhenThreadsLoseBeyondTheTolerance) {
  EXPECT_EQ(shared_cores_warning(8.5, 8.9, 2), "");
  EXPECT_EQ(shared_cores_warning(8.0, 10.0, 2), "");  // 25 % longer: at the tolerance
  EXPECT_EQ(shared_cores_warning(8.0, 16.0, 1), "");  // one thread: nothing shared
  EXPECT_EQ(shared_cores_warning(8.0, 11.0, 2, 0.5), "");
  // Session 64's host: 8.3 ms alone, 12.4 ms for one of two threads at once.
  const std::string shared = shared_cores_warning(8.3, 12.4, 2);
  EXPECT_NE(shared.find("8.3 ms on one thread, 12.4 ms on 2 at once"), std::string::npos) << shared;
}

TEST(BenchmarkMachine, DriftWarningOnlyWhenProbesMoveBeyondTheTolerance) {
  EXPECT_EQ(probe_drift_warning({}), "");
  EXPECT_EQ(probe_drift_warning({10.0}), "");
  EXPECT_EQ(probe_drift_warning({10.0, 12.5, 11.0}), "");  // 25 % apart: at the tolerance
  const std::string moved = probe_drift_warning({10.0, 12.6, 11.0});
  EXPECT_NE(moved.find("10.0-12.6 ms"), std::string::npos) << moved;
  EXPECT_EQ(probe_drift_warning({10.0, 14.0}, 0.5), "");
  EXPECT_NE(probe_drift_warning({18.7, 10.6}), "");  // session 32: beside a build, then idle
}
