// dgtex bench scenes: placeholder until its implementation lands.
#include <cstdio>

#include "commands.h"

namespace dgtex::cli {

int bench_scenes_command(int, char**) {
  std::fprintf(stderr, "dgtex bench scenes: not implemented yet\n");
  return 1;
}

}  // namespace dgtex::cli
