#include "gnuplot_chart.h"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace dgtex::cli {

bool draw_gnuplot_chart(const std::string& path, int width, int height, const std::string& data,
                        const std::function<std::string(const std::string& data_file)>& commands) {
  // gnuplot and the shell see only temporary names of plain characters: the scripts quote
  // file names with '...', which a name holding a quote would break. The chart is then
  // copied to PATH.
  static std::atomic<int> charts{0};
  const fs::path stem = fs::temp_directory_path() /
                        ("dgtex_chart_" + std::to_string(::getpid()) + "_" + std::to_string(charts++));
  const std::string data_path = stem.string() + ".dat", script_path = stem.string() + ".gp";
  const std::string image_path = stem.string() + ".image";
  std::ofstream(data_path) << data;
  const bool png = path.size() > 4 && path.substr(path.size() - 4) == ".png";
  const std::string size = " size " + std::to_string(width) + "," + std::to_string(height);
  const std::string body = "set output '" + image_path + "'\n" + commands(data_path) + "\n";
  auto run = [&](const std::string& terminal) {
    std::ofstream(script_path) << "set terminal " << terminal << size << "\n" << body;
    return std::system(("gnuplot '" + script_path + "' 2>/dev/null").c_str()) == 0;
  };
  const bool drawn = png ? (run("pngcairo") || run("png")) : run("svg");
  std::error_code copied, ignored;
  if (drawn) fs::copy_file(image_path, path, fs::copy_options::overwrite_existing, copied);
  for (const std::string& temporary : {script_path, data_path, image_path}) fs::remove(temporary, ignored);
  return drawn && !copied;
}

std::string gnuplot_quoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    if (c == '\n') {
      out += "\\n";
      continue;
    }
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

std::string bench_command_line(int argc, char** argv) {
  std::string command = "dgtex bench";
  for (int k = 0; k < argc; ++k) command += std::string(" ") + argv[k];
  return command;
}

std::string omp_wait_policy_name() {
  const char* policy = std::getenv("OMP_WAIT_POLICY");
  return policy ? policy : "default";
}

}  // namespace dgtex::cli
