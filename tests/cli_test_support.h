#pragma once
// Running the dgtex tool from a test: exit code and stderr of one command, and a fresh
// scratch folder per test process, removed at exit when every test passed.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

namespace dgtex::test {

struct CliResult {
  int exit_code;
  std::string stderr_text;
};

// Runs `dgtex ARGS` (stdout discarded), keeping stderr in WORKDIR/stderr.txt; ENVIRONMENT
// ("NAME=value ...", shell words) is set for that command only.
inline CliResult run_cli(const std::string& args, const std::filesystem::path& workdir,
                         const std::string& environment = "") {
  const std::filesystem::path err = workdir / "stderr.txt";
  const std::string command =
      environment + " " + std::string(DGTEX_CLI) + " " + args + " 2> " + err.string() + " > /dev/null";
  const int status = std::system(command.c_str());
  std::ifstream in(err);
  return {WEXITSTATUS(status), std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>())};
}

// The whole of a file as text ("" when it cannot be read).
inline std::string file_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// The scratch folders this process made. They go at exit when every test passed, so runs
// of the suite leave nothing behind; after a failure they stay to be looked at.
class ScratchFolders {
 public:
  void add(const std::filesystem::path& dir) { dirs_.push_back(dir); }
  ~ScratchFolders() {
    const bool passed = ::testing::UnitTest::GetInstance()->Passed();
    for (const std::filesystem::path& dir : dirs_) {
      if (!passed) {
        std::fprintf(stderr, "a test failed: kept its output in %s\n", dir.c_str());
        continue;
      }
      std::error_code ignored;
      std::filesystem::remove_all(dir, ignored);
    }
  }

 private:
  std::vector<std::filesystem::path> dirs_;
};

inline ScratchFolders& scratch_folders() {
  static ScratchFolders folders;
  return folders;
}

// An empty folder under the system's temporary folder, named after PREFIX, NAME and the pid.
inline std::filesystem::path fresh_dir(const std::string& prefix, const std::string& name) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / (prefix + "_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  scratch_folders().add(dir);
  return dir;
}

}  // namespace dgtex::test
