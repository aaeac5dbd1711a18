// dgtex bench laplace: the harmonic texel solvers side by side on identical systems.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "commands.h"
#include "count_option.h"
#include "gnuplot_chart.h"
#include "dgtex/benchmark_machine.h"
#include "dgtex/laplace_benchmark.h"
#include "dgtex/laplace_domains.h"
#include "dgtex/scene.h"
#include "dgtex/version.h"
#include "option_errors.h"
#include "output_paths.h"

namespace dgtex::cli {
namespace {

struct ChartSeries {
  std::string solver;
  std::vector<LaplaceConvergencePoint> points;
};

// Residual against time, one line per solver (PNG if the path ends in .png, else SVG).
std::string write_chart(const std::string& path, const std::string& title, const std::vector<ChartSeries>& series) {
  std::ostringstream data;
  for (const ChartSeries& s : series) {
    data << "# " << s.solver << "\n";
    for (const LaplaceConvergencePoint& p : s.points)
      data << std::max(p.ms, 1e-3) << " " << std::max(p.relative_residual, 1e-16) << "\n";
    data << "\n\n";
  }
  return draw_gnuplot_chart(path, 900, 600, data.str(), [&](const std::string& data_file) {
    std::ostringstream script;
    script << "set title '" << title << "'\nset logscale xy\nset xlabel 'time (ms)'\nset ylabel 'relative residual'\n"
           << "set format y '10^{%L}'\nset key outside right\nplot ";
    for (std::size_t k = 0; k < series.size(); ++k)
      script << (k ? ", " : "") << "'" << data_file << "' index " << k << " with linespoints title '"
             << series[k].solver << "' noenhanced";
    return script.str();
  });
}

}  // namespace

int bench_laplace_command(int argc, char** argv) {
  CLI::App app{"Time the harmonic-enrichment Laplace solvers to a common relative residual", "dgtex bench laplace"};
  std::vector<int> sizes = {128, 256, 512, 1024};
  std::vector<std::string> domains = {"open", "slit", "spiral", "accordion", "chad", "one_ring"};
  std::vector<std::string> solvers = {"multigrid", "multigrid_robust", "cholmod", "cholmod_solve", "eigen_ichol_cg",
                                      "boomeramg"};
  std::string json_path, chart_path, chart_domain = "slit";
  int chart_size = 512, repeat = 3;
  double tolerance = 1e-6;
  long max_other_unknowns = 2'000'000;
  app.add_option("--sizes", sizes, "texels per element side T")->delimiter(',')->check(whole_int());
  app.add_option("--domains", domains, "open, slit, spiral, accordion, chad, one_ring")->delimiter(',');
  app.add_option("--solvers", solvers, "multigrid, multigrid_robust, cholmod, cholmod_solve, eigen_ichol_cg, boomeramg")->delimiter(',');
  app.add_option("--json", json_path, "write the results as JSON")->check(writable_file());
  CLI::Option* chart_option =
      app.add_option("--chart", chart_path, "write residual against time (SVG, or PNG if FILE ends in .png)")
          ->check(writable_file());
  // Without a chart they were ignored, a bad value too.
  app.add_option("--chart-domain", chart_domain, "domain of the chart")->capture_default_str()->needs(chart_option);
  app.add_option("--chart-size", chart_size, "size T of the chart")
      ->capture_default_str()
      ->check(whole_int())
      ->needs(chart_option);
  app.add_option("--repeat", repeat, "runs per case; the best time counts")
      ->capture_default_str()
      ->check(at_least_one());
  app.add_option("--tolerance", tolerance, "relative residual to reach")->capture_default_str()->check(relative_tolerance());
  app.add_option("--max-other-unknowns", max_other_unknowns,
                 "skip solvers other than multigrid above this many unknowns")
      ->capture_default_str()
      ->check(whole_number(0, std::numeric_limits<long>::max()));
  try {
    app.parse(argc, argv);
    check_list_items(app, argc, argv);
  } catch (const CLI::ParseError& e) {
    return exit_on_option_error(app, e);
  }
  if (!outputs_are_distinct(app, {{"--json", &json_path}, {"--chart", &chart_path}})) return 2;
  // The chart's case must be one of the cases run, else it would be found missing at the end.
  if (!chart_path.empty() && std::find(domains.begin(), domains.end(), chart_domain) == domains.end()) {
    std::fprintf(stderr, "dgtex bench laplace: --chart-domain: %s is not among --domains; expected one of them\n",
                 chart_domain.c_str());
    return 2;
  }
  if (!chart_path.empty() && std::find(sizes.begin(), sizes.end(), chart_size) == sizes.end()) {
    std::fprintf(stderr, "dgtex bench laplace: --chart-size: %d is not among --sizes; expected one of them\n", chart_size);
    return 2;
  }
  try {
    std::vector<LaplaceDomain> domain_list;
    std::vector<LaplaceBenchSolver> solver_list;
    for (const std::string& d : domains) domain_list.push_back(parse_laplace_domain(d));
    for (const std::string& s : solvers) solver_list.push_back(parse_laplace_bench_solver(s));
    for (int T : sizes) {
      if (T < 16) throw std::invalid_argument("--sizes: T = " + std::to_string(T) + " is too small, need >= 16");
      // The largest texture a scene takes (enrichment.texture_resolution); beyond it the
      // texel arrays of one domain pass tens of gigabytes.
      if (T > kMaxTextureResolution)
        throw std::invalid_argument("--sizes: T = " + std::to_string(T) + " is too large, need <= " +
                                    std::to_string(kMaxTextureResolution));
    }

    const std::string machine = describe_machine_and_probe();
    std::printf("machine: %s\n", machine.c_str());
    nlohmann::json cases = nlohmann::json::array();
    std::vector<ChartSeries> chart;
    std::printf("%-10s %5s %9s  %-15s %10s %10s %6s %9s\n", "domain", "T", "unknowns", "solver", "ms", "residual", "iters",
                "setup_ms");
    for (LaplaceDomain domain : domain_list)
      for (int T : sizes) {
        const kernels::TexelTile problem = make_laplace_domain(domain, T);
        const TexelLaplaceSystem system = assemble_texel_laplace_system(problem);
        const long unknowns = static_cast<long>(system.b.size());
        const bool chart_case = !chart_path.empty() && laplace_domain_name(domain) == chart_domain && T == chart_size;
        for (LaplaceBenchSolver solver : solver_list) {
          const std::string name = laplace_bench_solver_name(solver);
          const bool is_multigrid = solver == LaplaceBenchSolver::multigrid || solver == LaplaceBenchSolver::multigrid_robust;
          if (!is_multigrid && unknowns > max_other_unknowns) {
            std::printf("%-10s %5d %9ld  %-15s %10s (skipped: over --max-other-unknowns)\n",
                        laplace_domain_name(domain).c_str(), T, unknowns, name.c_str(), "-");
            continue;
          }
          const LaplaceBenchRun run = run_laplace_bench_solver(solver, problem, system, tolerance, repeat, chart_case);
          std::printf("%-10s %5d %9ld  %-15s %10.2f %10.2e %6d", laplace_domain_name(domain).c_str(), T, unknowns,
                      name.c_str(), run.ms, run.residual, run.iterations);
          if (is_multigrid) std::printf(" %9.2f", run.setup_ms);
          std::printf("\n");
          std::fflush(stdout);
          cases.push_back({{"domain", laplace_domain_name(domain)}, {"size", T}, {"unknowns", unknowns},
                           {"solver", name}, {"ms", run.ms}, {"residual", run.residual},
                           {"iterations", run.iterations}, {"setup_ms", run.setup_ms}});
          if (chart_case) chart.push_back({name, run.history});
        }
      }
    // Speed-up of the multigrid over the other solvers, case by case, from this run.
    nlohmann::json ratios = nlohmann::json::array();
    for (const auto& mg : cases) {
      if (mg["solver"] != "multigrid") continue;
      nlohmann::json row = {{"domain", mg["domain"]}, {"size", mg["size"]}};
      std::string line;
      for (const auto& other : cases) {
        if (other["solver"] == "multigrid" || other["domain"] != mg["domain"] || other["size"] != mg["size"]) continue;
        const double ratio = other["ms"].get<double>() / mg["ms"].get<double>();
        row[other["solver"].get<std::string>()] = ratio;
        char buffer[64];
        std::snprintf(buffer, sizeof buffer, "  %s %.1fx", other["solver"].get<std::string>().c_str(), ratio);
        line += buffer;
      }
      if (line.empty()) continue;
      std::printf("speed-up of multigrid, %s T=%d:%s\n", mg["domain"].get<std::string>().c_str(), mg["size"].get<int>(),
                  line.c_str());
      ratios.push_back(row);
    }
    const int bandwidth_size = *std::max_element(sizes.begin(), sizes.end());
    const SmootherBandwidth bw = measure_smoother_bandwidth(bandwidth_size, std::max(5, repeat));
    std::printf("smoother (red-black sweep, T=%d): %.2f GB/s; array copy: %.2f GB/s; ratio %.0f%%\n", bandwidth_size,
                bw.smoother_gb_per_s, bw.copy_gb_per_s, 100.0 * bw.smoother_gb_per_s / bw.copy_gb_per_s);
    if (!json_path.empty()) {
      const nlohmann::json results{{"dgtex_version", version()},
                                   {"machine", machine},
                                   {"tolerance", tolerance},
                                   {"cases", cases},
                                   {"speedup_of_multigrid", ratios},
                                   {"smoother_bandwidth",
                                    {{"size", bandwidth_size},
                                     {"smoother_gb_per_s", bw.smoother_gb_per_s},
                                     {"copy_gb_per_s", bw.copy_gb_per_s}}}};
      write_output_file(json_path, results.dump(2) + "\n", "--json");
    }
    if (!chart_path.empty()) {
      if (chart.empty())
        std::fprintf(stderr, "dgtex bench laplace: no chart: --chart-domain %s / --chart-size %d is not among the cases\n",
                     chart_domain.c_str(), chart_size);
      else if (const std::string failure = write_chart(chart_path, chart_domain + ", T = " + std::to_string(chart_size), chart);
               !failure.empty()) {
        std::fprintf(stderr, "dgtex bench laplace: no chart '%s': %s\n", chart_path.c_str(), failure.c_str());
        return 1;
      }
    }
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "dgtex bench laplace: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dgtex bench laplace: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace dgtex::cli
