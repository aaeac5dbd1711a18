// `dgtex bench laplace` and `dgtex bench shell` from the command line: small runs write the
// JSON the README describes (the machine with its speed probe, every requested case, solver
// results that meet their bounds), and bad options exit with 2 and name the problem.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "cli_test_support.h"
#include "dgtex/version.h"

namespace fs = std::filesystem;
using dgtex::test::fresh_dir;
using dgtex::test::run_cli;

namespace {

nlohmann::json read_json(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

void expect_machine_with_probe(const nlohmann::json& j) {
  ASSERT_TRUE(j.contains("machine"));
  EXPECT_EQ(j["dgtex_version"], dgtex::version());  // which build measured
  EXPECT_NE(j["machine"].get<std::string>().find("one-core probe"), std::string::npos) << j["machine"];
}

TEST(BenchLaplaceCli, JsonHasEveryCaseAtTheToleranceAndTheMachine) {
  const fs::path dir = fresh_dir("dgtex_bench_laplace", "json");
  const fs::path json = dir / "laplace.json";
  const auto r = run_cli("bench laplace --sizes 32 48 --domains open slit --solvers multigrid cholmod --repeat 1"
                         " --tolerance 1e-7 --json " + json.string(), dir);
  ASSERT_EQ(r.exit_code, 0) << r.stderr_text;
  const nlohmann::json j = read_json(json);
  expect_machine_with_probe(j);
  EXPECT_EQ(j["tolerance"], 1e-7);
  std::set<std::string> seen;
  for (const auto& c : j["cases"]) {
    seen.insert(c["domain"].get<std::string>() + "/" + std::to_string(c["size"].get<int>()) + "/" +
                c["solver"].get<std::string>());
    EXPECT_LE(c["residual"].get<double>(), 1e-7) << c;
    EXPECT_GT(c["unknowns"].get<long>(), 0) << c;
    EXPECT_GT(c["ms"].get<double>(), 0.0) << c;
  }
  EXPECT_EQ(seen, (std::set<std::string>{"open/32/multigrid", "open/32/cholmod", "open/48/multigrid",
                                         "open/48/cholmod", "slit/32/multigrid", "slit/32/cholmod",
                                         "slit/48/multigrid", "slit/48/cholmod"}));
  EXPECT_EQ(j["speedup_of_multigrid"].size(), 4u);  // one row per domain and size
}

TEST(BenchLaplaceCli, BadOptionsExitWithTwoAndNameTheProblem) {
  const fs::path dir = fresh_dir("dgtex_bench_laplace", "bad");
  const auto small = run_cli("bench laplace --sizes 8", dir);
  EXPECT_EQ(small.exit_code, 2);
  EXPECT_NE(small.stderr_text.find("T = 8 is too small, need >= 16"), std::string::npos) << small.stderr_text;
  const auto domain = run_cli("bench laplace --domains nowhere", dir);
  EXPECT_EQ(domain.exit_code, 2);
  EXPECT_NE(domain.stderr_text.find("unknown Laplace domain 'nowhere'; valid: open"), std::string::npos)
      << domain.stderr_text;
  // Past the largest texture a scene takes, the texel arrays would fail to allocate.
  const auto large = run_cli("bench laplace --sizes 5000", dir);
  EXPECT_EQ(large.exit_code, 2);
  EXPECT_NE(large.stderr_text.find("T = 5000 is too large, need <= 4096"), std::string::npos) << large.stderr_text;
  const auto tolerance = run_cli("bench laplace --tolerance 0", dir);
  EXPECT_EQ(tolerance.exit_code, 2);
  EXPECT_NE(tolerance.stderr_text.find("--tolerance: Value 0 is not a relative tolerance a double-precision solve can "
                                       "reach; expected a number in [1e-12, 1)"),
            std::string::npos)
      << tolerance.stderr_text;
  const auto repeat = run_cli("bench laplace --repeat 0", dir);
  EXPECT_EQ(repeat.exit_code, 2);
  EXPECT_NE(repeat.stderr_text.find("--repeat: Value 0 not in range 1 to 2147483647"), std::string::npos)
      << repeat.stderr_text;
  const auto chart = run_cli("bench laplace --chart " + (dir / "stderr.txt" / "chart.svg").string(), dir);
  EXPECT_EQ(chart.exit_code, 2);
  EXPECT_NE(chart.stderr_text.find("--chart: '" + (dir / "stderr.txt").string() + "' is not a folder"),
            std::string::npos)
      << chart.stderr_text;
}

// Chart paths go to gnuplot through a shell and a script that quote names with '...': a
// folder named with a quote and a space must still get its chart (it got none before).
TEST(BenchLaplaceCli, ChartPathWithAQuoteAndASpace) {
  const fs::path work = fresh_dir("dgtex_bench_laplace", "quoted"), folder = work / "it's a folder";
  fs::create_directories(folder);
  const fs::path chart = folder / "residual.svg";
  const auto r = run_cli("bench laplace --sizes 16 --domains slit --solvers multigrid,cholmod --chart-domain slit"
                         " --chart-size 16 --chart \"" + chart.string() + "\"",
                         work);
  ASSERT_EQ(r.exit_code, 0) << r.stderr_text;
  ASSERT_TRUE(fs::exists(chart)) << r.stderr_text;
  std::ifstream in(chart);
  const std::string svg((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(svg.find("<svg"), std::string::npos);
  EXPECT_NE(svg.find("multigrid"), std::string::npos);  // the legend: the data reached the chart
}

TEST(BenchShellCli, JsonHasEveryThreadCountTheSameStateAndTheMachine) {
  const fs::path dir = fresh_dir("dgtex_bench_shell", "json");
  const fs::path json = dir / "shell.json";
  const auto r = run_cli("bench shell --scene " + std::string(DGTEX_SOURCE_DIR) +
                             "/examples/scenes/cylinder_buckling.json --steps 2 --threads-list 1 2 --gemm-size 64"
                             " --json " + json.string(),
                         dir);
  ASSERT_EQ(r.exit_code, 0) << r.stderr_text;
  const nlohmann::json j = read_json(json);
  expect_machine_with_probe(j);
  EXPECT_EQ(j["steps"], 2);
  EXPECT_EQ(j["omp_wait_policy"], "passive");  // the command restarts itself under it
  EXPECT_EQ(j["identical_across_threads"], true);
  ASSERT_EQ(j["cases"].size(), 2u);
  EXPECT_EQ(j["cases"][0]["threads"], 1);
  EXPECT_EQ(j["cases"][1]["threads"], 2);
  for (const auto& c : j["cases"]) {
    EXPECT_GT(c["assembly_ms"]["mean"].get<double>(), 0.0) << c;
    EXPECT_LE(c["step_ms"]["mean"].get<double>(), c["step_ms"]["max"].get<double>()) << c;
    EXPECT_GE(c["factorizations"].get<long>(), 1) << c;  // from rest: the first step factorises
  }
  EXPECT_EQ(j["counts"]["elements"], 961);  // the cylinder scene's mesh
  EXPECT_EQ(j["speedups"].size(), 1u);
}

// A chart gnuplot cannot draw ends the command with exit code 1 and the reason: gnuplot
// missing from PATH, or gnuplot's own error line (all said "is gnuplot installed?" before,
// and bench shell, laplace and render exited 0 without their chart).
TEST(BenchShellCli, AChartGnuplotCannotDrawExitsWithOneAndSaysWhy) {
  const fs::path dir = fresh_dir("dgtex_bench_shell", "chart");
  const fs::path bin = dir / "bin";
  fs::create_directories(bin);
  const std::string args = "bench shell --scene " + std::string(DGTEX_SOURCE_DIR) +
                           "/examples/scenes/cylinder_buckling.json --steps 1 --threads-list 1 --gemm-size 16 --chart " +
                           (dir / "chart.png").string();
  const auto missing = run_cli(args, dir, "PATH=" + bin.string());
  EXPECT_EQ(missing.exit_code, 1) << missing.stderr_text;
  EXPECT_NE(missing.stderr_text.find("no chart '" + (dir / "chart.png").string() +
                                     "': gnuplot is not installed (Debian: apt-get install gnuplot-nox)"),
            std::string::npos)
      << missing.stderr_text;
  // A gnuplot that fails as the real one does on a script it cannot plot.
  std::ofstream(bin / "gnuplot") << "#!/bin/sh\necho '    plot x' >&2\necho '         ^' >&2\n"
                                    "echo \"\\\"$1\\\", line 9: all points y value undefined!\" >&2\nexit 1\n";
  fs::permissions(bin / "gnuplot", fs::perms::owner_all);
  const auto failing = run_cli(args, dir, "PATH=" + bin.string());
  EXPECT_EQ(failing.exit_code, 1) << failing.stderr_text;
  EXPECT_NE(failing.stderr_text.find("': gnuplot failed: line 9: all points y value undefined!"), std::string::npos)
      << failing.stderr_text;
  EXPECT_FALSE(fs::exists(dir / "chart.png"));
}

TEST(BenchShellCli, BadOptionsExitWithTwoAndNameTheProblem) {
  const fs::path dir = fresh_dir("dgtex_bench_shell", "bad");
  const auto threads = run_cli("bench shell --threads-list 0", dir);
  EXPECT_EQ(threads.exit_code, 2);
  EXPECT_NE(threads.stderr_text.find("--threads-list: Value 0 not in range 1 to 1024"), std::string::npos)
      << threads.stderr_text;
  const auto scene = run_cli("bench shell --scene " + (dir / "missing.json").string(), dir);
  EXPECT_EQ(scene.exit_code, 2);
  EXPECT_NE(scene.stderr_text.find("missing.json"), std::string::npos) << scene.stderr_text;
}

}  // namespace
