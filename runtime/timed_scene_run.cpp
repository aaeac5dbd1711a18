#include "timed_scene_run.h"

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

}  // namespace dgtex::detail
