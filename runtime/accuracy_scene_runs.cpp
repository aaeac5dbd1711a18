#include "accuracy_scene_runs.h"

#include <cmath>

namespace dgtex::detail {

TimedSceneRun run_scene_timed(const Scene& scene, int steps, AccuracyClock clock,
                              const std::function<void(const SceneRun& run, int step)>& after_step) {
  TimedSceneRun out;
  const double start = accuracy_clock_ms(clock);
  SceneRun run(scene);
  for (int k = 1; k <= steps; ++k) {
    run.step();
    after_step(run, k);
  }
  out.ms = accuracy_clock_ms(clock) - start;
  const StageTimings timings = run.timings();
  if (const auto it = timings.find("assembly"); it != timings.end()) out.assembly_wall_ms = it->second.total_ms;
  return out;
}

std::string scene_file_name(const std::string& path) { return path.substr(path.find_last_of('/') + 1); }

double squared_distance(const std::vector<double>& a, const std::vector<double>& b) {
  double sum = 0;
  for (std::size_t k = 0; k < a.size(); ++k) sum += (a[k] - b[k]) * (a[k] - b[k]);
  return sum;
}

double squared_norm(const std::vector<double>& a) {
  double sum = 0;
  for (double v : a) sum += v * v;
  return sum;
}

double relative_root(double squared, double squared_scale) {
  return squared_scale > 0 ? std::sqrt(squared / squared_scale) : std::sqrt(squared);
}

}  // namespace dgtex::detail
