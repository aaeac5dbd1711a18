// Tolerance sweep of dgtex bench accuracy: how much accuracy each solver tolerance buys.
//  - shell: the corotated dynamic step's PCG with a reused factor (FactorReusingSolver),
//    final displacement after N steps against factorising every step (direct solves);
//  - multigrid: the texel Laplace multigrid on the slit domain, against CHOLMOD.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>

#include <omp.h>

#include "dgtex/accuracy_benchmark.h"
#include "dgtex/laplace_domains.h"
#include "dgtex/laplace_solver.h"
#include "dgtex/shell_benchmark.h"
#include "accuracy_scene_runs.h"
#include "api_argument_checks.h"

namespace dgtex {
namespace {

std::string tolerance_label(double tol) {
  char label[32];
  std::snprintf(label, sizeof label, "tol=%g", tol);
  return label;
}

void shell_points(const ToleranceAccuracyOptions& options, const AccuracyProgress& progress, AccuracyChart& chart) {
  const int threads = omp_get_max_threads();
  const std::string series = "shell PCG (" + std::to_string(options.shell_steps) + " steps)";
  const ShellBenchRun reference = run_shell_benchmark(options.shell_scene, options.shell_steps, threads, false);
  const double reference_squared_norm = detail::squared_norm(reference.displacement);
  auto add = [&](const std::string& label, const ShellBenchRun& run, double error) {
    AccuracyPoint p;
    p.series = series;
    p.label = label;
    // The steps' assembly + solve: run_shell_benchmark measures CPU time per whole step.
    p.ms = options.clock == AccuracyClock::cpu ? run.step_cpu.total_ms : run.step.total_ms;
    p.error = error;
    p.extra = {{"pcg_iterations", static_cast<double>(run.pcg_iterations)},
               {"factorizations", static_cast<double>(run.factorizations)},
               {"free_dofs", static_cast<double>(run.free_dofs)},
               {"solve_wall_ms", run.solve.total_ms}};
    chart.points.push_back(p);
    if (progress) {
      char line[220];
      std::snprintf(line, sizeof line,
                    "tolerance shell %-22s: %9.1f ms over %d steps, %ld factorisations, %ld PCG iterations, "
                    "error %.3e",
                    label.c_str(), p.ms, options.shell_steps, run.factorizations, run.pcg_iterations, error);
      progress(line);
    }
  };
  add("factorise every step", reference, 0.0);
  for (double tol : options.shell_tolerances) {
    FactorReuseOptions solver;
    solver.relative_tolerance = tol;
    const ShellBenchRun run = run_shell_benchmark(options.shell_scene, options.shell_steps, threads, true, solver);
    if (run.displacement.size() != reference.displacement.size())
      throw std::logic_error("tolerance accuracy: DOF counts of the runs differ");
    const double squared_error = detail::squared_distance(run.displacement, reference.displacement);
    add(tolerance_label(tol), run, detail::relative_root(squared_error, reference_squared_norm));
  }
}

void multigrid_points(const ToleranceAccuracyOptions& options, const AccuracyProgress& progress, AccuracyChart& chart) {
  const int T = options.multigrid_resolution;
  const std::string series = "texel multigrid (slit, T=" + std::to_string(T) + ")";
  const kernels::TexelTile problem = make_laplace_domain(LaplaceDomain::slit, T);
  auto timed_solve = [&](LaplaceSolver solver, const LaplaceMultigridOptions& mg, kernels::TexelTile& out,
                         LaplaceSolveStats& stats) {
    double best = std::numeric_limits<double>::infinity();
    for (int r = 0; r < std::max(1, options.repeat); ++r) {
      out = problem;
      const double start = accuracy_clock_ms(options.clock);
      stats = solve_laplace(out, solver, mg);
      best = std::min(best, accuracy_clock_ms(options.clock) - start);
    }
    return best;
  };
  kernels::TexelTile reference;
  LaplaceSolveStats stats;
  const double reference_ms = timed_solve(LaplaceSolver::cholmod, {}, reference, stats);
  auto add = [&](const std::string& label, double ms, double error, int iterations) {
    AccuracyPoint p;
    p.series = series;
    p.label = label;
    p.ms = ms;
    p.error = error;
    p.extra = {{"iterations", iterations}};
    chart.points.push_back(p);
    if (progress) {
      char line[200];
      std::snprintf(line, sizeof line, "tolerance multigrid %-10s: %8.2f ms, %3d iterations, max |H - H_CHOLMOD| %.3e",
                    label.c_str(), ms, iterations, error);
      progress(line);
    }
  };
  add("CHOLMOD", reference_ms, 0.0, 0);
  for (double tol : options.multigrid_tolerances) {
    LaplaceMultigridOptions mg;
    mg.tolerance = tol;
    mg.warm_start = false;
    kernels::TexelTile solution;
    const double ms = timed_solve(LaplaceSolver::multigrid, mg, solution, stats);
    double error = 0;
    for (std::size_t k = 0; k < solution.values.size(); ++k)
      error = std::max(error, std::abs(solution.values[k] - reference.values[k]));
    add(tolerance_label(tol), ms, error, stats.iterations);
  }
}

}  // namespace

void check_tolerance_accuracy_options(const ToleranceAccuracyOptions& options) {
  if (!options.shell && !options.multigrid)
    throw std::invalid_argument("tolerance accuracy: neither the shell nor the multigrid series is on; the chart would be "
                                "empty");
  if (options.shell && options.shell_steps < 1)
    throw std::invalid_argument("tolerance accuracy: shell steps = " + std::to_string(options.shell_steps) +
                                "; need >= 1");
  // Before the sweeps: a scene that did not load ended the command after the others' work.
  if (options.shell) load_shell_benchmark_scene(options.shell_scene);
  for (const auto& [series, list] : {std::pair{"shell", &options.shell_tolerances},
                                      std::pair{"multigrid", &options.multigrid_tolerances}})
    for (double tol : *list)
      if (!(tol >= detail::kMinRelativeTolerance && tol < 1))
        throw std::invalid_argument("tolerance accuracy: " + std::string(series) + " tolerance " +
                                    detail::short_number(tol) + "; need " +
                                    detail::short_number(detail::kMinRelativeTolerance) + " <= tol < 1");
  // The slit domain's size (T = 3 was refused only after the shell series had run; T =
  // 100000 ended in a bare std::bad_alloc). Its reference is a CHOLMOD solve, which at T =
  // 2048 took 63 s and 3.1 GB (dgtex bench laplace, 2-core EPYC); 4096 has 4x the texels.
  const int T = options.multigrid_resolution;
  if (options.multigrid && (T < 16 || T > 2048))
    throw std::invalid_argument("tolerance accuracy: multigrid size T = " + std::to_string(T) +
                                "; need 16..2048 (its reference is a CHOLMOD solve)");
}

AccuracyChart run_tolerance_accuracy(const ToleranceAccuracyOptions& options, const AccuracyProgress& progress) {
  check_tolerance_accuracy_options(options);
  AccuracyChart chart;
  chart.name = "tolerance";
  chart.title = "solver tolerance against time";
  chart.time_label = accuracy_clock_name(options.clock) + " ms: shell, all steps (assembly + solve); multigrid, one solve";
  chart.error_label = "shell: |u - u_ref| / |u_ref| vs factorising every step; multigrid: max |H - H_CHOLMOD|";
  if (options.shell) shell_points(options, progress, chart);
  if (options.multigrid) multigrid_points(options, progress, chart);
  return chart;
}

}  // namespace dgtex
