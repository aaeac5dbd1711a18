#include "gnuplot_chart.h"

#include <cstdio>
#include <cstdlib>
#include <fstream>

namespace dgtex::cli {

bool draw_gnuplot_chart(const std::string& path, int width, int height, const std::string& data,
                        const std::function<std::string(const std::string& data_file)>& commands) {
  const std::string data_path = path + ".dat", script_path = path + ".gp";
  std::ofstream(data_path) << data;
  const bool png = path.size() > 4 && path.substr(path.size() - 4) == ".png";
  const std::string size = " size " + std::to_string(width) + "," + std::to_string(height);
  const std::string body = "set output '" + path + "'\n" + commands(data_path) + "\n";
  auto run = [&](const std::string& terminal) {
    std::ofstream(script_path) << "set terminal " << terminal << size << "\n" << body;
    return std::system(("gnuplot '" + script_path + "' 2>/dev/null").c_str()) == 0;
  };
  const bool ok = png ? (run("pngcairo") || run("png")) : run("svg");
  std::remove(script_path.c_str());
  std::remove(data_path.c_str());
  return ok;
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
