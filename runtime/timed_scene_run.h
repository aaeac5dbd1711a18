#pragma once
// Internal: a whole scene run timed for the accuracy sweeps that vary a scene setting
// (rotation clusters, quadrature merge tolerance): set-up, steps and cut updates in one time.
#include <functional>

#include "dgtex/accuracy_benchmark.h"
#include "dgtex/scene_run.h"

namespace dgtex::detail {

struct TimedSceneRun {
  double ms = 0;                // the whole run by the sweep's clock
  double assembly_wall_ms = 0;  // the run's assembly stage (wall time)
};

// Sets the scene up and takes `steps` steps, calling after_step(run, k) after step k
// (1-based; where a sweep reads the state, at the end when k == steps).
TimedSceneRun run_scene_timed(const Scene& scene, int steps, AccuracyClock clock,
                              const std::function<void(const SceneRun& run, int step)>& after_step);

}  // namespace dgtex::detail
