#pragma once
// How every command ends on its command line's errors: --help prints the help (exit 0);
// a bad option or value is one line on stderr naming the command, the option and the
// value, with where to look (exit 2), as for bad scenes. CLI11's own exit() would add a
// second line ("Run with --help for more information.").
#include <CLI/CLI.hpp>
#include <cstdio>
#include <string>
#include <vector>

namespace dgtex::cli {

// CLI11 drops the empty items of a comma-separated list ("--sizes 16,,32," ran 16 and 32)
// and keeps repeats ("--tessellations 1,1" ran and reported the case twice): both are
// refused, as a CLI::ValidationError naming the option. Call after app.parse; it reads
// the list options' values as given on the command line.
inline void check_list_items(const CLI::App& app, int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string argument = argv[i];
    if (argument.rfind("--", 0) != 0) continue;
    const std::size_t equals = argument.find('=');
    const std::string name = argument.substr(0, equals);
    const CLI::Option* option = app.get_option_no_throw(name);
    if (option == nullptr || option->get_delimiter() != ',') continue;
    std::string value;
    if (equals != std::string::npos)
      value = argument.substr(equals + 1);
    else if (i + 1 < argc)
      value = argv[++i];
    std::vector<std::string> items;
    for (std::size_t start = 0;;) {
      const std::size_t comma = value.find(',', start);
      items.push_back(value.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    for (std::size_t k = 0; k < items.size(); ++k) {
      if (items[k].empty())
        throw CLI::ValidationError(name, "'" + value + "' has an empty item; expected values separated by single commas");
      for (std::size_t j = 0; j < k; ++j)
        if (items[j] == items[k])
          throw CLI::ValidationError(name, "'" + value + "' names " + items[k] + " twice; expected each value once");
    }
  }
}

inline int exit_on_option_error(CLI::App& app, const CLI::ParseError& error) {
  if (error.get_exit_code() == 0) return app.exit(error);  // --help
  std::fprintf(stderr, "%s: %s (see %s --help)\n", app.get_name().c_str(), error.what(), app.get_name().c_str());
  return 2;
}

}  // namespace dgtex::cli
