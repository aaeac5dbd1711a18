// The machine line and speed probe of the benchmark reports (dgtex/benchmark_machine.h).
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "dgtex/benchmark_machine.h"

using namespace dgtex;

TEST(BenchmarkMachine, DescriptionNamesTheCoresAndThreads) {
  const int saved = omp_get_max_threads();
  omp_set_num_threads(1);
  const std::string one = describe_machine();
  omp_set_num_threads(3);
  const std::string three = describe_machine();
  omp_set_num_threads(saved);
  EXPECT_NE(one.find(" cores, 1 thread"), std::string::npos) << one;
  EXPECT_NE(three.find(" cores, 3 threads"), std::string::npos) << three;
}

TEST(BenchmarkMachine, ProbeTimesItsWorkloadAndRejectsNoRuns) {
  // 2^25 multiply-adds: well above the clock's resolution on any machine, below a second
  // on any that runs the test suite in its time limit (about 10 ms on the 2-core machine).
  const double ms = machine_probe_ms(1);
  EXPECT_TRUE(std::isfinite(ms));
  EXPECT_GT(ms, 0.1);
  EXPECT_LT(ms, 2000.0);
  EXPECT_THROW(machine_probe_ms(0), std::invalid_argument);
  // The charts' heading: the description, then the probe.
  const std::string heading = describe_machine_and_probe();
  EXPECT_EQ(heading.rfind(describe_machine() + ", one-core probe ", 0), 0u) << heading;
  EXPECT_EQ(heading.substr(heading.size() - 3), " ms") << heading;
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
