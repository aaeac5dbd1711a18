#pragma once
// The example scenes of thesis Table 5.1, stepped the way `dgtex run` steps them
// (dgtex/scene_run.h), with per-step stage timings next to the thesis's figures
// (`dgtex bench scenes`).
//
// Per step: "enrichment" (cut update and Laplace solves), "projection" (basis change: new
// model, projection of the state; only steps where the functions changed), "assembly",
// "solve", and the whole step (wall clock and process CPU time). The enrichment update
// at time 0, done while the run is built, is counted in step 1 (enrichment and whole
// step), so a scene whose cuts are present from the start shows its one big update there.
// Plain functions that return their results (nothing kept); each uses all OpenMP threads,
// so run one at a time. Times in ms (wall clock and CPU).
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "dgtex/scene.h"
#include "dgtex/scene_run.h"

namespace dgtex {

// One row of thesis Table 5.1 (ms per step on an Intel Core2 Duo 2.4 GHz; t_enr is the
// peak over the run, t_asm and t_sol the mean).
struct ThesisTable51Row {
  const char* model;  // as the thesis names it
  int elements, nodes, enrichments, texture_resolution;
  double enrichment_ms, assembly_ms, solve_ms;
};

// The Table 5.1 row of a bench scene name (chad, spiral1, spiral6, accordion, slinky,
// fracture -> the thesis's "Bunny", a fractured triangle mesh), or null (cylinder_buckling
// and any other name: no thesis figure).
const ThesisTable51Row* thesis_table_5_1_row(const std::string& scene_name);

// The scenes `dgtex bench scenes` runs by default, in table order: the six of Table 5.1
// and cylinder_buckling.
const std::vector<std::string>& bench_scene_names();

// Sizes of the model at the end of the run: the same quantities (and JSON keys, see the
// CLI) as the counts of `dgtex run`'s report.
struct SceneCounts {
  std::int64_t elements = 0, nodes = 0, dofs = 0, enriched_dofs = 0, free_dofs = 0, nonzeros = 0,
               factor_nonzeros = 0, interior_edges = 0, clamped_edges = 0, quadrature_points = 0,
               enriched_elements = 0, enriched_quadrature_points = 0, enrichments = 0, texture_resolution = 0,
               basis_changes = 0, rotation_clusters = 0, rotation_cluster_bytes = 0;
};

// Milliseconds per step, one entry per step taken.
struct SceneStepTimes {
  std::vector<double> enrichment, projection, assembly, solve;
  std::vector<double> step;      // wall clock of the whole step
  std::vector<double> step_cpu;  // process CPU time of the whole step (all threads summed)
  // Per step, the factor-reusing solver's PCG iterations (those of a stale factor that
  // failed included) and numeric factorisations (corotational scenes; a linear scene
  // factorises outside it and counts 0).
  std::vector<std::int64_t> pcg_iterations, factorizations;
  // Per step, the OpenMP threads of the cut update that ran beside it (0: none did).
  std::vector<int> cut_update_threads;
};

// What a scene trades accuracy for speed with (scene file keys): the stages' times mean little
// without them.
struct SceneAccuracySettings {
  double time_step = 0;             // analysis.time_step (s)
  double quadrature_tolerance = 0;  // enrichment.quadrature_tolerance
  int rotation_cluster_texels = 0;  // enrichment.rotation_cluster_texels (0: per point)
};

struct SceneBenchResult {
  std::string name;      // bench name (file stem)
  std::string path;      // scene file
  int threads = 1;       // OpenMP threads it ran with
  bool overlap_cut_updates = true;  // SceneRunOptions it ran with (dgtex/scene_run.h)
  int steps = 0;         // steps taken
  int scene_steps = 0;   // the scene's own analysis.steps (fewer taken: a partial run)
  double setup_ms = 0;   // building mesh, model and simulation, without the time-0 enrichment
  SceneStepTimes times;  // per step (step 1 includes the time-0 enrichment update)
  SceneCounts counts;
  SceneAccuracySettings settings;
  std::vector<double> displacement;  // final (all DOFs), for identity checks

  double steps_per_second() const;          // steps / total step wall time
  double peak_step_ms() const;              // slowest step (its enrichment, projection, assembly, solve)
};

// Mean and maximum of a series (0 for an empty one).
double series_mean(const std::vector<double>& v);
double series_max(const std::vector<double>& v);
double series_median(std::vector<double> v);

// Throws std::invalid_argument, naming the scene, unless it is a dynamic analysis (what
// run_scene_benchmark steps; for a caller that checks its scenes before running any).
void check_scene_benchmark_scene(const Scene& scene);

// Runs a dynamic scene from rest for `steps` steps (0: the scene's own analysis.steps)
// with the current OpenMP thread count. `progress(step, steps)` (may be empty) is called
// after every step. Throws std::invalid_argument for a static scene or steps < 0, and
// what SceneRun throws (SceneError, MeshError, ModelError) for a scene that does not build;
// ModelError when the solution stops being finite (naming the step).
// `options`: how SceneRun orders each step (overlapped cut updates by default).
SceneBenchResult run_scene_benchmark(const Scene& scene, const std::string& name, int steps,
                                     const std::function<void(int step, int steps)>& progress = {},
                                     const SceneRunOptions& options = {});

}  // namespace dgtex
