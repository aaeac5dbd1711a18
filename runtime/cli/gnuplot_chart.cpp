#include "gnuplot_chart.h"

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace fs = std::filesystem;

namespace dgtex::cli {

std::string draw_gnuplot_chart(const std::string& path, int width, int height, const std::string& data,
                               const std::function<std::string(const std::string& data_file)>& commands) {
  // gnuplot and the shell see only temporary names of plain characters: the scripts quote
  // file names with '...', which a name holding a quote would break. The chart is then
  // copied to PATH.
  static std::atomic<int> charts{0};
  const fs::path stem = fs::temp_directory_path() /
                        ("dgtex_chart_" + std::to_string(::getpid()) + "_" + std::to_string(charts++));
  const std::string data_path = stem.string() + ".dat", script_path = stem.string() + ".gp";
  const std::string image_path = stem.string() + ".image", errors_path = stem.string() + ".err";
  std::ofstream(data_path) << data;
  std::string extension = fs::path(path).extension().string();  // x.PNG is a PNG too, as for dgtex render
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const bool png = extension == ".png";
  const std::string size = " size " + std::to_string(width) + "," + std::to_string(height);
  const std::string body = "set output '" + image_path + "'\n" + commands(data_path) + "\n";
  int status = 0;
  auto run = [&](const std::string& terminal) {
    std::ofstream(script_path) << "set terminal " << terminal << size << "\n" << body;
    status = std::system(("gnuplot '" + script_path + "' 2>'" + errors_path + "'").c_str());
    return status == 0;
  };
  const bool drawn = png ? (run("pngcairo") || run("png")) : run("svg");
  std::string failure;
  if (!drawn && WIFEXITED(status) && WEXITSTATUS(status) == 127) {
    failure = "gnuplot is not installed (Debian: apt-get install gnuplot-nox)";
  } else if (!drawn) {
    // gnuplot's last message line names the script line and the problem.
    std::ifstream errors(errors_path);
    std::string line, last;
    while (std::getline(errors, line))
      if (line.find_first_not_of(" \t^") != std::string::npos) last = line;
    const std::string script_prefix = "\"" + script_path + "\", ";
    if (last.rfind(script_prefix, 0) == 0) last = last.substr(script_prefix.size());
    failure = "gnuplot failed" + (last.empty() ? std::string() : ": " + last);
  } else {
    std::error_code copied;
    fs::copy_file(image_path, path, fs::copy_options::overwrite_existing, copied);
    if (copied) failure = "cannot write it: " + copied.message();
  }
  std::error_code ignored;
  for (const std::string& temporary : {script_path, data_path, image_path, errors_path}) fs::remove(temporary, ignored);
  return failure;
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
