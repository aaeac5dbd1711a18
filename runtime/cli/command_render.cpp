// Placeholder until this command is implemented.
#include <cstdio>

#include "commands.h"

namespace dgtex::cli {

int render_command(int, char**) {
  std::fprintf(stderr, "dgtex: 'render' is not implemented yet\n");
  return 1;
}

}  // namespace dgtex::cli
