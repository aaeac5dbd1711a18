#include "dgtex/benchmark_machine.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <vector>

namespace dgtex {

std::string describe_machine() {
  std::string model = "unknown CPU";
  std::ifstream cpuinfo("/proc/cpuinfo");
  for (std::string line; std::getline(cpuinfo, line);)
    if (line.rfind("model name", 0) == 0) {
      const auto colon = line.find(':');
      if (colon != std::string::npos) model = line.substr(line.find_first_not_of(" \t", colon + 1));
      break;
    }
  std::ostringstream out;
  out << model << ", " << std::thread::hardware_concurrency() << " cores, " << omp_get_max_threads()
      << (omp_get_max_threads() == 1 ? " thread" : " threads");
  return out.str();
}

double machine_probe_ms(int repeats) {
  if (repeats < 1) throw std::invalid_argument("machine_probe_ms: repeats must be >= 1, got " + std::to_string(repeats));
  constexpr int chains = 16;
  constexpr long rounds = (1L << 25) / chains;
  // Volatile inputs and output: the compiler can neither fold the chains nor drop them,
  // and the store of their sum, before the clock is read again, keeps them inside the timing.
  volatile double factor_in = 1.0000001, offset_in = 1e-9, sink = 0;
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < repeats; ++r) {
    const double factor = factor_in, offset = offset_in;
    double a[chains];
    for (int k = 0; k < chains; ++k) a[k] = k;
    const auto start = std::chrono::steady_clock::now();
    for (long i = 0; i < rounds; ++i)
      for (int k = 0; k < chains; ++k) a[k] = a[k] * factor + offset;
    double sum = 0;
    for (int k = 0; k < chains; ++k) sum += a[k];
    sink = sink + sum;
    best = std::min(best, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  return best;
}

double machine_probe_all_threads_ms(int threads, int repeats) {
  if (threads < 1)
    throw std::invalid_argument("machine_probe_all_threads_ms: threads must be >= 1, got " + std::to_string(threads));
  if (repeats < 1)
    throw std::invalid_argument("machine_probe_all_threads_ms: repeats must be >= 1, got " + std::to_string(repeats));
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < repeats; ++r) {
    std::vector<double> ms(threads, 0.0);
#pragma omp parallel num_threads(threads)
    {
#pragma omp barrier
      ms[omp_get_thread_num()] = machine_probe_ms(1);
    }
    best = std::min(best, *std::max_element(ms.begin(), ms.end()));
  }
  return best;
}

std::string shared_cores_warning(double one_core_ms, double all_threads_ms, int threads, double tolerance) {
  if (threads < 2 || all_threads_ms <= (1 + tolerance) * one_core_ms) return {};
  char text[320];
  std::snprintf(text, sizeof text,
                "the host did not give each of the %d threads a core of its own: the probe took %.1f ms on one "
                "thread, %.1f ms on %d at once (more than %.0f %% longer); multithreaded figures are below this "
                "machine's",
                threads, one_core_ms, all_threads_ms, threads, 100 * tolerance);
  return text;
}

std::string probe_drift_warning(const std::vector<double>& probes_ms, double tolerance) {
  if (probes_ms.size() < 2) return {};
  const auto [fastest, slowest] = std::minmax_element(probes_ms.begin(), probes_ms.end());
  if (*slowest <= (1 + tolerance) * *fastest) return {};
  char text[256];
  std::snprintf(text, sizeof text,
                "the machine's speed changed during the run: the one-core probe took %.1f-%.1f ms (more than %.0f %% "
                "apart); compare these figures with care",
                *fastest, *slowest, 100 * tolerance);
  return text;
}

std::string describe_machine_and_probe() {
  char probe[128];
  const int threads = omp_get_max_threads();
  if (threads > 1)
    std::snprintf(probe, sizeof probe, ", one-core probe %.1f ms (%d threads at once: %.1f ms)", machine_probe_ms(),
                  threads, machine_probe_all_threads_ms(threads));
  else
    std::snprintf(probe, sizeof probe, ", one-core probe %.1f ms", machine_probe_ms());
  return describe_machine() + probe;
}

}  // namespace dgtex
