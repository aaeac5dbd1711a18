// Google Benchmark cases of `dgtex bench shell`: the corotated dynamic step of the
// cylinder buckling scene (thesis Fig. 5.3) at 1 and 2 threads, with counters for the
// assembly and solve time per step, quadrature points per second and assembly GFLOP/s
// (flop model: shell_assembly_flops), and the Eigen dense GEMM reference of the same run.
// The full table with JSON output is `dgtex bench shell`.
#include <benchmark/benchmark.h>
#include <omp.h>

#include <string>

#include "dgtex/shell_benchmark.h"

namespace {

const std::string scene = std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/cylinder_buckling.json";

void corotated_step(benchmark::State& state, bool reuse_factorization) {
  const int threads = static_cast<int>(state.range(0));
  const int steps = static_cast<int>(state.range(1));
  dgtex::ShellBenchRun run;
  for (auto _ : state) {
    run = dgtex::run_shell_benchmark(scene, steps, threads, reuse_factorization);
    state.SetIterationTime(run.step.total_ms * 1e-3 / steps);  // time per step
  }
  state.counters["assembly_ms"] = run.assembly.mean_ms();
  state.counters["solve_ms"] = run.solve.mean_ms();
  state.counters["step_max_ms"] = run.step.max_ms;
  state.counters["qp_per_s"] = run.quadrature_points_per_s;
  state.counters["assembly_GFLOPs"] = run.assembly_gflops;
  state.counters["factorizations"] = static_cast<double>(run.factorizations);
  state.counters["pcg_iterations"] = static_cast<double>(run.pcg_iterations);
  state.SetLabel(std::to_string(threads) + " threads, " + std::to_string(steps) + " steps");
}

void dense_gemm(benchmark::State& state) {
  omp_set_num_threads(static_cast<int>(state.range(0)));
  double gflops = 0;
  for (auto _ : state) gflops = dgtex::measure_dense_gemm_gflops(static_cast<int>(state.range(1)), 1);
  state.counters["GFLOPs"] = gflops;
}

}  // namespace

BENCHMARK_CAPTURE(corotated_step, pcg_reused_factor, true)
    ->Args({1, 30})->Args({2, 30})->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK_CAPTURE(corotated_step, refactor_every_step, false)
    ->Args({1, 10})->Args({2, 10})->UseManualTime()->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(dense_gemm)->Args({1, 512})->Args({2, 512})->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
