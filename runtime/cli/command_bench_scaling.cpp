// dgtex bench scaling: placeholder until its implementation lands.
#include <cstdio>

#include "commands.h"

namespace dgtex::cli {

int bench_scaling_command(int, char**) {
  std::fprintf(stderr, "dgtex bench scaling: not implemented yet\n");
  return 1;
}

}  // namespace dgtex::cli
