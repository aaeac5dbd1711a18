// Placeholder until this command is implemented.
#include <cstdio>

#include "commands.h"

namespace dgtex::cli {

int bench_shell_command(int, char**) {
  std::fprintf(stderr, "dgtex: 'bench_shell' is not implemented yet\n");
  return 1;
}

}  // namespace dgtex::cli
