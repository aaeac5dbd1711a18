#pragma once
// How every command ends on its command line's errors: --help prints the help (exit 0);
// a bad option or value is one line on stderr naming the command, the option and the
// value, with where to look (exit 2), as for bad scenes. CLI11's own exit() would add a
// second line ("Run with --help for more information.").
#include <CLI/CLI.hpp>
#include <cstdio>

namespace dgtex::cli {

inline int exit_on_option_error(CLI::App& app, const CLI::ParseError& error) {
  if (error.get_exit_code() == 0) return app.exit(error);  // --help
  std::fprintf(stderr, "%s: %s (see %s --help)\n", app.get_name().c_str(), error.what(), app.get_name().c_str());
  return 2;
}

}  // namespace dgtex::cli
