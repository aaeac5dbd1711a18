// dgtex: command-line front end of the library. Dispatches on the sub-command name.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "commands.h"
#include "dgtex/version.h"

namespace {

void print_usage(std::FILE* to) {
  std::fprintf(to,
               "usage: dgtex <command> [options]\n"
               "commands:\n"
               "  run SCENE.json --out DIR     simulate a scene, write report, meshes and images\n"
               "  render STATE --out DIR|PNG   render a saved state to PNG\n"
               "  bench laplace [options]      Laplace solvers on texel domains (multigrid, CHOLMOD, ...)\n"
               "  bench shell [options]        shell assembly and solve throughput\n"
               "  bench render [options]       cut-boundary error against triangles drawn, frame times\n"
               "  bench scenes [options]       the thesis Table 5.1 scenes: per-step stage timings, steps/s\n"
               "  bench scaling [options]      thread scaling per kernel family, batch throughput\n"
               "  bench accuracy [options]     error against time charts (plate, quadrature, T, tolerance)\n"
               "Run 'dgtex <command> --help' for the options of one command; 'dgtex --version' prints the\n"
               "library's version.\n");
}

}  // namespace

int main(int argc, char** argv) {
  // OpenMP threads that wait by spinning (libgomp's default) take the cores from each other
  // and from the rest of the machine: with 2 threads on 2 busy cores a shell step measured
  // 0.3-0.5x the speed of 1 thread spinning, 1.0-1.1x waiting passively. libgomp reads
  // OMP_WAIT_POLICY once, when it loads, so without the variable the tool starts itself
  // again with it set to passive (an explicit setting is kept).
  if (!std::getenv("OMP_WAIT_POLICY")) {
    setenv("OMP_WAIT_POLICY", "passive", 1);
    execv("/proc/self/exe", argv);  // returns only on failure: then go on as we are
  }
  if (argc >= 2 && !std::strcmp(argv[1], "--version")) {
    if (argc > 2) {
      std::fprintf(stderr, "dgtex: --version takes no arguments, got '%s'\n", argv[2]);
      return 2;
    }
    std::printf("dgtex %s\n", dgtex::version());
    return 0;
  }
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    print_usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  const std::string command = argv[1];
  if (command == "run") return dgtex::cli::run_command(argc - 1, argv + 1);
  if (command == "render") return dgtex::cli::render_command(argc - 1, argv + 1);
  if (command == "bench") {
    const std::string what = argc > 2 ? argv[2] : "";
    if (what == "laplace") return dgtex::cli::bench_laplace_command(argc - 2, argv + 2);
    if (what == "shell") return dgtex::cli::bench_shell_command(argc - 2, argv + 2);
    if (what == "render") return dgtex::cli::bench_render_command(argc - 2, argv + 2);
    if (what == "scenes") return dgtex::cli::bench_scenes_command(argc - 2, argv + 2);
    if (what == "scaling") return dgtex::cli::bench_scaling_command(argc - 2, argv + 2);
    if (what == "accuracy") return dgtex::cli::bench_accuracy_command(argc - 2, argv + 2);
    if (what == "--help" || what == "-h") {
      std::printf("Usage: dgtex bench BENCHMARK [OPTIONS]; benchmarks: laplace, shell, render, scenes, scaling, "
                  "accuracy (dgtex bench BENCHMARK --help for each one's options)\n");
      return 0;
    }
    if (what.empty())
      std::fprintf(stderr, "dgtex bench: which benchmark? (valid: laplace, shell, render, scenes, scaling, accuracy)\n");
    else
      std::fprintf(stderr,
                   "dgtex bench: unknown benchmark '%s' (valid: laplace, shell, render, scenes, scaling, accuracy)\n",
                   what.c_str());
    return 2;
  }
  std::fprintf(stderr, "dgtex: unknown command '%s'\n", command.c_str());
  print_usage(stderr);
  return 2;
}
