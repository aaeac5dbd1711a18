// Google Benchmark cases for the harmonic texel solvers: time to relative residual 1e-6
// from a zero initial guess, per domain and size (the full side-by-side table, BoomerAMG
// included, is `dgtex bench laplace`).
#include <benchmark/benchmark.h>

#include "dgtex/laplace_benchmark.h"
#include "dgtex/laplace_domains.h"

namespace {

void laplace_solve(benchmark::State& state, dgtex::LaplaceBenchSolver solver) {
  const auto domain = static_cast<dgtex::LaplaceDomain>(state.range(0));
  const int T = static_cast<int>(state.range(1));
  const dgtex::kernels::TexelTile problem = dgtex::make_laplace_domain(domain, T);
  const dgtex::TexelLaplaceSystem system = dgtex::assemble_texel_laplace_system(problem);
  double residual = 0;
  for (auto _ : state) {
    const dgtex::LaplaceBenchRun run = dgtex::run_laplace_bench_solver(solver, problem, system, 1e-6, 1, false);
    state.SetIterationTime(run.ms * 1e-3);
    residual = run.residual;
  }
  state.counters["residual"] = residual;
  state.SetLabel(dgtex::laplace_domain_name(domain) + " T=" + std::to_string(T));
}

void domains_and_sizes(benchmark::internal::Benchmark* b, std::vector<long> sizes) {
  for (dgtex::LaplaceDomain d : dgtex::all_laplace_domains())
    for (long T : sizes)
      if (d != dgtex::LaplaceDomain::one_ring || T <= 256) b->Args({static_cast<long>(d), T});
  b->UseManualTime()->Unit(benchmark::kMillisecond);
}

}  // namespace

BENCHMARK_CAPTURE(laplace_solve, multigrid, dgtex::LaplaceBenchSolver::multigrid)
    ->Apply([](benchmark::internal::Benchmark* b) { domains_and_sizes(b, {128, 256, 512, 1024}); });
BENCHMARK_CAPTURE(laplace_solve, multigrid_robust, dgtex::LaplaceBenchSolver::multigrid_robust)
    ->Apply([](benchmark::internal::Benchmark* b) { domains_and_sizes(b, {128, 256, 512, 1024}); });
BENCHMARK_CAPTURE(laplace_solve, cholmod, dgtex::LaplaceBenchSolver::cholmod)
    ->Apply([](benchmark::internal::Benchmark* b) { domains_and_sizes(b, {128, 256, 512}); });
BENCHMARK_CAPTURE(laplace_solve, eigen_ichol_cg, dgtex::LaplaceBenchSolver::eigen_ichol_cg)
    ->Apply([](benchmark::internal::Benchmark* b) { domains_and_sizes(b, {128, 256}); });

BENCHMARK_MAIN();
