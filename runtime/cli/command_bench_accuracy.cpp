// dgtex bench accuracy: placeholder until its implementation lands.
#include <cstdio>

#include "commands.h"

namespace dgtex::cli {

int bench_accuracy_command(int, char**) {
  std::fprintf(stderr, "dgtex bench accuracy: not implemented yet\n");
  return 1;
}

}  // namespace dgtex::cli
