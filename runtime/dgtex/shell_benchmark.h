#pragma once
// Throughput of the shell time step (dgtex bench shell, examples/bench_shell.cpp): runs a
// dynamic scene for a number of steps at a given OpenMP thread count and reports the time
// per step split into assembly and solve, quadrature points per second and the achieved
// GFLOP/s of the assembly (counted with shell_assembly_flops, below), next to an Eigen
// dense matrix product measured in the same process as the attainable reference.
// Plain functions that return their measurements (nothing kept); they set the OpenMP
// thread count themselves, so run one at a time, and restore the caller's count before
// they return. Times in ms, rates per second.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "dgtex/factor_reusing_solver.h"
#include "dgtex/scene.h"
#include "dgtex/shell_model.h"
#include "dgtex/stage_timer.h"

namespace dgtex {

struct ShellBenchRun {
  int threads = 1;
  int steps = 0;
  bool reuse_factorization = true;
  std::int64_t elements = 0, nodes = 0, free_dofs = 0, quadrature_points = 0, factor_nonzeros = 0;
  StageStatistics assembly, solve, step;  // ms per step (wall clock)
  // Process CPU time per step, all threads summed: on a shared machine, with 1 thread it
  // approximates the wall time the step would take on an idle core.
  StageStatistics step_cpu;
  double assembly_flops = 0;              // counted flops of one corotated assembly
  double quadrature_points_per_s = 0;     // (element + edge points) / mean assembly time
  double assembly_gflops = 0;             // assembly_flops / mean assembly time
  std::vector<double> assembly_ms, solve_ms;  // per step
  long factorizations = 0, pcg_iterations = 0;
  double factorize_ms = 0, precondition_ms = 0;  // totals inside the solve stage
  std::vector<double> displacement;       // final state (for the thread-independence check)
};

// Loads the scene at `scene_path` and checks that the benchmark can time it; returns it.
// Throws SceneError for a scene that does not load, std::invalid_argument for one that is
// not a dynamic analysis or has cuts.
Scene load_shell_benchmark_scene(const std::string& scene_path);

// Throws as load_shell_benchmark_scene, std::invalid_argument for steps < 1, and MeshError
// for a mesh that does not build. progress (optional) is called after every step with
// (steps done, steps).
ShellBenchRun run_shell_benchmark(const std::string& scene_path, int steps, int threads,
                                  bool reuse_factorization = true, const FactorReuseOptions& solver = {},
                                  const std::function<void(int, int)>& progress = {});

// Counted floating-point operations of one assemble_stiffness call (corotated when
// `corotated`): exact for the K and force products of the element and edge kernels,
// per-point estimates for the geometry (documented in shell_benchmark.cpp).
double shell_assembly_flops(const ShellModel& model, bool corotated);

// GFLOP/s of an Eigen dense n x n matrix product (2 n^3 flops; best of `repeat`) with the
// current OpenMP thread count.
double measure_dense_gemm_gflops(int n = 512, int repeat = 3);

}  // namespace dgtex
