// dgtex bench shell: time per dynamic step (assembly, solve), assembly throughput against
// an Eigen dense GEMM measured in the same run, and the speed-up over thread counts.
#include <CLI/CLI.hpp>
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "commands.h"
#include "count_option.h"
#include "example_scenes.h"
#include "gnuplot_chart.h"
#include "dgtex/benchmark_machine.h"
#include "dgtex/mesh_error.h"
#include "dgtex/scene_io.h"
#include "dgtex/shell_benchmark.h"
#include "dgtex/version.h"
#include "option_errors.h"
#include "output_paths.h"

namespace dgtex::cli {
namespace {

// Median of per-step times: robust to other processes taking the cores for a while.
double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

nlohmann::json stage_json(const StageStatistics& s, const std::vector<double>& per_step = {}) {
  nlohmann::json j = {{"mean", s.mean_ms()}, {"max", s.max_ms}};
  if (!per_step.empty()) j["median"] = median(per_step);
  return j;
}

// Milliseconds per step (assembly and solve, one line per thread count) with gnuplot.
std::string write_chart(const std::string& path, const std::vector<ShellBenchRun>& runs) {
  std::ostringstream data;
  for (const ShellBenchRun& r : runs) {
    data << "# threads " << r.threads << "\n";
    for (std::size_t s = 0; s < r.assembly_ms.size(); ++s)
      data << s + 1 << " " << r.assembly_ms[s] << " " << r.solve_ms[s] << "\n";
    data << "\n\n";
  }
  return draw_gnuplot_chart(path, 900, 600, data.str(), [&](const std::string& data_file) {
    std::ostringstream script;
    script << "set title 'dgtex bench shell: time per step'\nset xlabel 'step'\nset ylabel 'ms'\nset logscale y\n"
           << "set key outside right\nplot ";
    for (std::size_t k = 0; k < runs.size(); ++k) {
      const std::string t = std::to_string(runs[k].threads);
      script << (k ? ", " : "") << "'" << data_file << "' index " << k << " using 1:2 with lines title 'assembly, " << t
             << " threads', '" << data_file << "' index " << k << " using 1:3 with lines title 'solve, " << t
             << " threads'";
    }
    return script.str();
  });
}

}  // namespace

int bench_shell_command(int argc, char** argv) {
  CLI::App app{"Time the dynamic shell step of a scene: assembly and solve per step, assembly GFLOP/s against an "
               "Eigen dense GEMM, speed-up over thread counts",
               "dgtex bench shell"};
  std::string scene_path = example_scene("cylinder_buckling.json"), json_path, chart_path;
  int steps = 30, gemm_size = 512;
  std::vector<int> threads_list = {1, 2};
  bool refactor_every_step = false;
  FactorReuseOptions solver;
  app.add_option("--scene", scene_path, "dynamic scene (JSON)")->capture_default_str()->check(CLI::ExistingFile);
  // Per-step times are kept (two doubles a step): 2^31 steps would take 32 GiB of them.
  app.add_option("--steps", steps, "time steps per case (from rest)")->capture_default_str()->check(whole_number(1, 1000000));
  app.add_option("--threads-list", threads_list, "OpenMP thread counts, one case each")
      ->delimiter(',')
      ->capture_default_str()
      ->check(thread_count());
  app.add_option("--json", json_path, "write the results as JSON")->check(writable_file());
  app.add_option("--chart", chart_path, "write ms per step (SVG, or PNG if FILE ends in .png) with gnuplot")
      ->check(writable_file());
  app.add_option("--gemm-size", gemm_size, "n of the n x n Eigen GEMM reference")
      ->capture_default_str()
      ->check(at_least_one());
  CLI::Option* tolerance_option =
      app.add_option("--tolerance", solver.relative_tolerance, "PCG relative residual bound per step")
          ->capture_default_str()
          ->check(relative_tolerance());
  CLI::Option* refactor_after_option =
      app.add_option("--refactor-after", solver.refactor_after_iterations,
                     "refactorise when a step needed more PCG iterations than this")
          ->capture_default_str()
          ->check(zero_or_more());
  std::string preconditioner = "element_local";
  CLI::Option* preconditioner_option =
      app.add_option("--preconditioner", preconditioner,
                     "pattern of the PCG preconditioner's factor: element_local (the default) or full")
          ->capture_default_str()
          ->check(CLI::IsMember({"element_local", "full"}));
  bool synchronous_factorization = false;
  CLI::Option* synchronous_option = app.add_flag(
      "--synchronous-factorization", synchronous_factorization,
      "factorise a stale preconditioner at the start of the next solve instead of beside the next assembly");
  // The PCG options mean nothing to the direct path: given with it, they were ignored.
  app.add_flag("--refactor-every-step", refactor_every_step,
               "reference solver path: factorise the corotated matrix every step (no PCG)")
      ->excludes(tolerance_option)
      ->excludes(refactor_after_option)
      ->excludes(preconditioner_option)
      ->excludes(synchronous_option);
  std::string wait_policy = "passive";
  app.add_option("--omp-wait-policy", wait_policy,
                 "OMP_WAIT_POLICY to run under (passive, active, or inherit): with libgomp's spinning default, "
                 "2 threads on 2 busy cores measured 3x slower than 1")
      ->capture_default_str()
      ->check(CLI::IsMember({"passive", "active", "inherit"}));
  try {
    app.parse(argc, argv);
    check_list_items(app, argc, argv);
  } catch (const CLI::ParseError& e) {
    return exit_on_option_error(app, e);
  }
  if (!outputs_are_distinct(app, {{"--json", &json_path}, {"--chart", &chart_path}}, {{"the scene of --scene", scene_path}}))
    return 2;
  if (!thread_counts_increase(app, threads_list)) return 2;
  // a, b and c = a b: three n x n matrices of doubles.
  const std::optional<std::int64_t> available = memory_for_options(app);
  if (!available) return 2;
  if (const std::int64_t most = most_that_fit(std::int64_t{gemm_size} * gemm_size, 3 * 8, *available); most >= 0) {
    std::fprintf(stderr,
                 "dgtex bench shell: --gemm-size: %d: three n x n matrices would not fit the %s of memory available; "
                 "expected at most %lld (see dgtex bench shell --help)\n",
                 gemm_size, memory_size_text(*available).c_str(),
                 static_cast<long long>(std::sqrt(static_cast<double>(most))));
    return 2;
  }
  solver.preconditioner_pattern =
      preconditioner == "full" ? PreconditionerPattern::full : PreconditionerPattern::element_local;
  solver.overlap_factorization = !synchronous_factorization;
  // libgomp reads OMP_WAIT_POLICY once, when it loads: to change it, run again under it.
  const char* current_policy = std::getenv("OMP_WAIT_POLICY");
  if (wait_policy != "inherit" && (!current_policy || wait_policy != current_policy)) {
    setenv("OMP_WAIT_POLICY", wait_policy.c_str(), 1);
    std::vector<char*> args = {const_cast<char*>("dgtex"), const_cast<char*>("bench"), const_cast<char*>("shell")};
    for (int k = 1; k < argc; ++k) args.push_back(argv[k]);
    args.push_back(nullptr);
    execv("/proc/self/exe", args.data());
    std::fprintf(stderr, "dgtex bench shell: could not restart under OMP_WAIT_POLICY=%s; continuing with %s\n",
                 wait_policy.c_str(), current_policy ? current_policy : "the default");
  }
  try {
    const std::string machine = describe_machine_and_probe();
    std::printf("machine: %s\n", machine.c_str());
    std::vector<ShellBenchRun> runs;
    std::vector<double> gemm;
    const auto print_header = [] {
      std::printf("%-7s %8s %8s %8s %8s %8s %8s %8s %8s %8s %8s %8s %6s %7s\n", "threads", "step_ms", "step_max",
                "cpu_ms", "asm_ms", "asm_med", "asm_max", "solve_ms", "solve_med", "solve_max", "Mqp/s", "GFLOP/s",
                "facts", "pcg_its");
    };
    for (int threads : threads_list) {
      // A line every 10 s on a long run (a million steps take hours).
      auto last_line = std::chrono::steady_clock::now();
      const auto progress = [&](int step, int total) {
        if (std::chrono::steady_clock::now() - last_line < std::chrono::seconds(10)) return;
        last_line = std::chrono::steady_clock::now();
        std::fprintf(stderr, "bench shell: %d thread%s, step %d/%d\n", threads, threads == 1 ? "" : "s", step, total);
      };
      runs.push_back(run_shell_benchmark(scene_path, steps, threads, !refactor_every_step, solver, progress));
      if (runs.size() == 1) print_header();  // after the scene loaded: errors come alone
      omp_set_num_threads(threads);
      gemm.push_back(measure_dense_gemm_gflops(gemm_size));
      const ShellBenchRun& r = runs.back();
      std::printf("%-7d %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %8.2f %8.3f %8.2f %6ld %7ld\n", threads,
                  r.step.mean_ms(), r.step.max_ms, r.step_cpu.mean_ms(), r.assembly.mean_ms(), median(r.assembly_ms),
                  r.assembly.max_ms, r.solve.mean_ms(), median(r.solve_ms), r.solve.max_ms,
                  r.quadrature_points_per_s / 1e6, r.assembly_gflops, r.factorizations, r.pcg_iterations);
      std::fflush(stdout);
    }
    const ShellBenchRun& first = runs.front();
    for (std::size_t k = 0; k < runs.size(); ++k)
      std::printf("threads %d: Eigen dense GEMM (n = %d) %.2f GFLOP/s; assembly reaches %.1f%% of it\n", runs[k].threads,
                  gemm_size, gemm[k], 100 * runs[k].assembly_gflops / gemm[k]);
    std::printf("scene %s: %lld elements, %lld nodes, %lld free DOFs, %lld quadrature points, nnz(L) %lld, "
                "%.1f MFLOP per assembly (counted)\n",
                scene_path.c_str(), static_cast<long long>(first.elements), static_cast<long long>(first.nodes),
                static_cast<long long>(first.free_dofs), static_cast<long long>(first.quadrature_points),
                static_cast<long long>(first.factor_nonzeros), first.assembly_flops / 1e6);
    bool identical = true;
    for (const ShellBenchRun& r : runs) identical = identical && r.displacement == first.displacement;
    std::printf("final displacement bitwise identical across thread counts: %s\n", identical ? "yes" : "NO");
    nlohmann::json speedups = nlohmann::json::array();
    for (std::size_t k = 1; k < runs.size(); ++k) {
      const ShellBenchRun& r = runs[k];
      const nlohmann::json s = {{"from_threads", first.threads}, {"to_threads", r.threads},
                                {"step", first.step.mean_ms() / r.step.mean_ms()},
                                {"assembly", first.assembly.mean_ms() / r.assembly.mean_ms()},
                                {"solve", first.solve.mean_ms() / r.solve.mean_ms()}};
      std::printf("speed-up %d -> %d threads: step %.2fx, assembly %.2fx, solve %.2fx\n", first.threads, r.threads,
                  s["step"].get<double>(), s["assembly"].get<double>(), s["solve"].get<double>());
      speedups.push_back(s);
    }
    if (!json_path.empty()) {
      nlohmann::json cases = nlohmann::json::array();
      for (std::size_t k = 0; k < runs.size(); ++k) {
        const ShellBenchRun& r = runs[k];
        cases.push_back({{"threads", r.threads},
                         {"step_ms", stage_json(r.step)},
                         {"step_cpu_ms", stage_json(r.step_cpu)},
                         {"assembly_ms", stage_json(r.assembly, r.assembly_ms)},
                         {"solve_ms", stage_json(r.solve, r.solve_ms)},
                         {"quadrature_points_per_s", r.quadrature_points_per_s},
                         {"assembly_gflops", r.assembly_gflops},
                         {"gemm_gflops", gemm[k]},
                         {"assembly_fraction_of_gemm", gemm[k] > 0 ? r.assembly_gflops / gemm[k] : 0.0},
                         {"factorizations", r.factorizations},
                         {"pcg_iterations", r.pcg_iterations},
                         {"factorize_ms_total", r.factorize_ms},
                         {"precondition_ms_total", r.precondition_ms}});
      }
      const nlohmann::json results{{"dgtex_version", version()},
                                   {"machine", machine},
                                   {"scene", scene_path},
                                   {"steps", steps},
                                   {"solver", refactor_every_step ? "refactor_every_step" : "pcg_reused_factor"},
                                   {"pcg_relative_tolerance", solver.relative_tolerance},
                                   {"omp_wait_policy", omp_wait_policy_name()},
                                   {"refactor_after_iterations", solver.refactor_after_iterations},
                                   {"preconditioner", preconditioner},
                                   {"overlap_factorization", solver.overlap_factorization},
                                   {"counts",
                                    {{"elements", first.elements},
                                     {"nodes", first.nodes},
                                     {"free_dofs", first.free_dofs},
                                     {"quadrature_points", first.quadrature_points},
                                     {"factor_nonzeros", first.factor_nonzeros}}},
                                   {"assembly_flops", first.assembly_flops},
                                   {"gemm_size", gemm_size},
                                   {"cases", cases},
                                   {"speedups", speedups},
                                   {"identical_across_threads", identical}};
      write_output_file(json_path, results.dump(2) + "\n", "--json");
    }
    if (const std::string failure = chart_path.empty() ? "" : write_chart(chart_path, runs); !failure.empty()) {
      std::fprintf(stderr, "dgtex bench shell: no chart '%s': %s\n", chart_path.c_str(), failure.c_str());
      return 1;
    }
  } catch (const SceneError& e) {
    std::fprintf(stderr, "dgtex bench shell: %s\n", e.what());
    return 2;
  } catch (const MeshError& e) {
    std::fprintf(stderr, "dgtex bench shell: %s: mesh: %s\n", scene_path.c_str(), e.what());
    return 2;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "dgtex bench shell: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dgtex bench shell: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace dgtex::cli
