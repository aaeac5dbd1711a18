#pragma once
// The machine a benchmark ran on, for its report: what it is, and how fast it ran then.
// The same build can run at very different speeds on machines of one kind, and on one
// machine from day to day (session 32's 2-core host ran every scene ~2.5x slower than
// session 31's), so a figure is only comparable with one taken beside the same yardstick.
#include <string>
#include <vector>

namespace dgtex {

// "MODEL NAME, N cores" from /proc/cpuinfo (or "unknown CPU"), plus the OpenMP threads.
std::string describe_machine();

// Milliseconds that the calling thread takes for a fixed arithmetic workload held in
// registers (2^25 multiply-adds in 16 independent chains): the best of `repeats` runs.
// No memory traffic and no other thread, so it shows the speed of one core as the host
// gives it now (lower is faster). Throws std::invalid_argument for repeats < 1.
double machine_probe_ms(int repeats = 3);

// The same workload on `threads` threads at once (an OpenMP team; each thread times its own
// run): the slowest thread's time, the best of `repeats` runs. Where the host gives every
// thread a core of its own this equals machine_probe_ms; a core shared with another tenant
// (a busy SMT sibling, time stolen by the hypervisor) makes it longer, which the one-core
// probe cannot see (session 64's host at one moment: 8.3-8.7 ms alone, 10.2-12.4 ms for a
// thread of two at once). Neither probe sees contention for memory or cache: through that
// session's slow runs (scenes 25-40 % slower than in session 63) both read as in session 63.
// Throws std::invalid_argument for threads < 1 or repeats < 1.
double machine_probe_all_threads_ms(int threads, int repeats = 3);

// A warning when the probe on all threads at once took more than `tolerance` longer than
// on one (the host did not give each thread a core of its own: multithreaded figures are
// below the machine's). Empty otherwise, and for one thread.
std::string shared_cores_warning(double one_core_ms, double all_threads_ms, int threads, double tolerance = 0.25);

// A warning when probes taken during one benchmark run differ by more than `tolerance`
// (0.25: the slowest more than 25 % above the fastest): the host's speed changed under the
// run, so its figures do not compare with each other or with another run. Empty otherwise
// (also for fewer than two probes).
std::string probe_drift_warning(const std::vector<double>& probes_ms, double tolerance = 0.25);

// describe_machine() and ", one-core probe X ms" (machine_probe_ms now), with more than one
// OpenMP thread also " (N threads at once: Y ms)" (machine_probe_all_threads_ms): a chart's heading.
std::string describe_machine_and_probe();

}  // namespace dgtex
