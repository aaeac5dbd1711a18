#pragma once
// Charts of the bench commands, drawn by gnuplot (Debian gnuplot-nox), and what a bench
// report states about its run (command line, wait policy).
#include <functional>
#include <string>

namespace dgtex::cli {

// Draws into `path`: PNG if it ends in .png, in any case (pngcairo, or the plain png terminal where the
// gnuplot build lacks cairo), else SVG, width x height pixels. `data` goes to a temporary
// file; `commands(data_file)` returns the settings and plot commands, referring to the data
// by that file name (plain characters, safe inside '...'). gnuplot draws into a temporary
// file too, copied to `path` at the end, so any `path` works. The temporary files are
// removed. Returns "" when the chart was drawn, else why not: gnuplot is not installed,
// gnuplot's own error (e.g. "line 9: all points y value undefined!"), or the copy to
// `path` failed.
std::string draw_gnuplot_chart(const std::string& path, int width, int height, const std::string& data,
                               const std::function<std::string(const std::string& data_file)>& commands);

// A gnuplot double-quoted string (newlines become line breaks there).
std::string gnuplot_quoted(const std::string& text);

// The command a bench chart states: "dgtex bench" and the subcommand's own arguments
// (argv[0] is the subcommand's name).
std::string bench_command_line(int argc, char** argv);

// OMP_WAIT_POLICY as the bench reports state it: the variable's value, or "default".
std::string omp_wait_policy_name();

}  // namespace dgtex::cli
