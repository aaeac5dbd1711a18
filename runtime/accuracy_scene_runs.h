#pragma once
// Internal: the scene runs of the accuracy sweeps that vary a scene setting (rotation
// clusters, quadrature merge tolerance): a whole run timed (set-up, steps and cut updates in
// one time), the distances their errors are made of (also the solver tolerance sweep's),
// and the series name of a scene file.
#include <functional>
#include <string>
#include <vector>

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

// The scene file's name without its folders: the sweep's series name.
std::string scene_file_name(const std::string& path);

// |a - b|^2 over a's entries (b holds at least as many), and |a|^2.
double squared_distance(const std::vector<double>& a, const std::vector<double>& b);
double squared_norm(const std::vector<double>& a);
// sqrt(squared / squared_scale): a relative error from the two; the absolute sqrt(squared)
// where the scale is 0 (a reference at rest).
double relative_root(double squared, double squared_scale);

}  // namespace dgtex::detail
