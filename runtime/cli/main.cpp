// dgtex: command-line front end of the library. Dispatches on the sub-command name.
#include <cstdio>
#include <cstring>
#include <string>

#include "commands.h"

namespace {

void print_usage(std::FILE* to) {
  std::fprintf(to,
               "usage: dgtex <command> [options]\n"
               "commands:\n"
               "  run SCENE.json --out DIR     simulate a scene, write report, meshes and images\n"
               "  render STATE --out DIR       render a saved state to PNG\n"
               "  bench laplace [options]      Laplace solvers on texel domains (multigrid, CHOLMOD, ...)\n"
               "  bench shell [options]        shell assembly and solve throughput\n"
               "Run 'dgtex <command> --help' for the options of one command.\n");
}

}  // namespace

int main(int argc, char** argv) {
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
    std::fprintf(stderr, "dgtex bench: unknown benchmark '%s' (valid: laplace, shell)\n", what.c_str());
    return 2;
  }
  std::fprintf(stderr, "dgtex: unknown command '%s'\n", command.c_str());
  print_usage(stderr);
  return 2;
}
