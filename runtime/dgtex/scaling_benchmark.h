#pragma once
// Thread scaling of the kernel families of a shell step, and batch throughput of
// independent scenes (`dgtex bench scaling`).
//
// Kernel families, each timed at every requested OpenMP thread count (best wall time of
// `repeats` runs, so other processes on a shared machine disturb it least):
//  - enrichment solve: CutManager::update of a cut scene at the time its cuts are complete
//    (rasterisation plus the Laplace solves of every function, from scratch);
//  - assembly: ShellModel::assemble_stiffness, corotated, of a plain scene and of a cut
//    scene with its complete cuts' enrichments;
//  - polar decomposition: kernels::polar_decomposition_batch over random 3x3 matrices;
//  - factorization: SparseCholesky::factorize of M + dt^2 K over the free DOFs;
//  - scene step: SceneRun::step, whole steps of a scene (ms per step).
// Batch throughput: K independent runs of one scene (setup and S steps each), either
// one after another with all threads each ("solo") or at once in K std::threads with one
// OpenMP thread each ("batch"); scenes per second both ways, and whether every run ends
// in bitwise the same displacement (results do not depend on the thread count).
// Plain functions that return their results (nothing kept); they set the OpenMP thread
// count themselves, so run one at a time, and restore the caller's count before they
// return. Times in ms.
#include <cstdint>
#include <string>
#include <vector>

#include "dgtex/scene.h"

namespace dgtex {

struct KernelScaling {
  std::string family;    // enrichment_solve, assembly, polar_decomposition, factorization, scene_step
  std::string workload;  // what was timed (scene, sizes)
  std::vector<int> threads;
  std::vector<double> ms;  // per thread count: best of the repeats (scene_step: mean ms per step)
  // Final results bitwise equal for every thread count (checked where the family has one).
  bool identical_across_threads = true;
};

// What a family needs of its scene: "enrichment_solve" and "enriched_assembly" need cuts;
// "factorization", "scene_step" and "batch" a dynamic analysis. Throws std::invalid_argument
// naming the scene (its source_name) and the family where the scene lacks it. The families
// check it themselves; a tool calls it first, to refuse a scene before any family runs.
void check_scaling_scene(const Scene& scene, const std::string& family);

// Time of the complete cuts' enrichment update (CutManager from scratch, update at the
// scene's end time). Throws std::invalid_argument for a scene without cuts.
KernelScaling scale_enrichment_solve(const Scene& cut_scene, const std::vector<int>& threads, int repeats);
// Corotated assemble_stiffness at a fixed deformed state (rest state plus a smooth
// perturbation). With `complete_cuts`, the scene's cuts at its end time enrich the model.
KernelScaling scale_assembly(const Scene& scene, bool complete_cuts, const std::vector<int>& threads, int repeats);
// polar_decomposition_batch over `count` random matrices with det > 0 (fixed seed).
KernelScaling scale_polar_decomposition(std::int64_t count, const std::vector<int>& threads, int repeats);
// Numeric CHOLMOD factorisation of M + dt^2 K (linear K, the scene's fixed DOFs; the
// symbolic analysis is done once, untimed). The scene must be dynamic and have no cuts.
KernelScaling scale_factorization(const Scene& scene, const std::vector<int>& threads, int repeats);
// Mean ms per step over `steps` steps (after one untimed step) of a fresh SceneRun.
KernelScaling scale_scene_steps(const Scene& scene, int steps, const std::vector<int>& threads);

struct BatchThroughput {
  std::string scene;
  int runs = 0;          // K
  int steps = 0;         // S per run
  int solo_threads = 0;  // threads of each solo run
  double solo_ms = 0;    // wall time of the K solo runs one after another
  double batch_ms = 0;   // wall time of the K runs at once
  double solo_scenes_per_second() const { return solo_ms > 0 ? 1e3 * runs / solo_ms : 0.0; }
  double batch_scenes_per_second() const { return batch_ms > 0 ? 1e3 * runs / batch_ms : 0.0; }
  bool identical = true;  // every run (solo and batch) ends in bitwise the same displacement
  // Largest difference of any run's final displacement from the first solo run's, over
  // the largest magnitude of the latter (0 when identical).
  double max_relative_difference = 0;
  std::vector<double> displacement;  // final displacement of the first batch member
};

// K = runs >= 1, S = steps >= 1; solo runs use `solo_threads` OpenMP threads, batch
// members one each. Exceptions of a batch member are rethrown here.
BatchThroughput measure_batch_throughput(const Scene& scene, int runs, int steps, int solo_threads);

}  // namespace dgtex
