// End-to-end with cuts: `dgtex run` on scenes with complete and progressive cuts (the
// enrichment textures, the enriched shell and the basis change with projection together).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_test_support.h"

namespace fs = std::filesystem;

namespace {

using Result = dgtex::test::CliResult;

fs::path fresh_dir(const std::string& name) { return dgtex::test::fresh_dir("dgtex_cli_cuts", name); }

Result run_scene(const nlohmann::json& scene, const fs::path& dir, const std::string& extra = "") {
  const fs::path scene_path = dir / "scene.json";
  std::ofstream(scene_path) << scene.dump(1);
  return dgtex::test::run_cli("run " + scene_path.string() + " --out " + (dir / "out").string() + " --quiet " + extra,
                              dir);
}

nlohmann::json report_of(const fs::path& dir) {
  std::ifstream in(dir / "out" / "report.json");
  return nlohmann::json::parse(in);
}

// A strip [0, 1] x [0, 0.25] of 4 quad8 clamped at x = 0 under gravity, cut across at
// x = 0.625 (inside the third element, on a texel edge at T = 32).
nlohmann::json cut_strip() {
  return nlohmann::json::parse(R"({
    "mesh": {"generator": "rectangle", "size": [1, 0.25], "divisions": [4, 1], "element": "quad8"},
    "material": {"youngs_modulus": 1e9, "poisson_ratio": 0.3, "thickness": 0.02, "density": 1000},
    "penalty": 1,
    "boundary": [{"select": {"plane": {"normal": [1, 0, 0], "offset": 0}}, "fix": ["x", "y", "z"], "clamp": true}],
    "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81]}],
    "analysis": {"type": "dynamic", "time_step": 0.001, "steps": 40, "corotational": true},
    "probes": [{"name": "free_end", "position": [1, 0.125, 0]}, {"name": "before_cut", "position": [0.4, 0.125, 0]}],
    "cuts": [{"points": [[0.625, -0.01, 0], [0.625, 0.26, 0]]}],
    "enrichment": {"texture_resolution": 32}
  })");
}

TEST(CliCuts, CompletelyCutPieceFallsFreelyWhileTheClampedPartHolds) {
  const fs::path dir = fresh_dir("complete");
  nlohmann::json scene = cut_strip();
  scene["material"]["youngs_modulus"] = 2e11;  // a stiff cantilever: see below
  scene["material"]["thickness"] = 0.05;
  const Result r = run_scene(scene, dir, "--save-textures --no-render --no-memory-reserve");
  ASSERT_EQ(r.exit_code, 0) << r.stderr_text;
  const nlohmann::json report = report_of(dir);
  EXPECT_EQ(report["reserved_step_memory_bytes"], 0);
  EXPECT_EQ(report["counts"]["enrichments"], 1);
  EXPECT_EQ(report["counts"]["enriched_dofs"], 3 * 8);  // the nodes of the one cut element
  EXPECT_EQ(report["counts"]["basis_changes"], 0);       // present from the start
  // The free piece falls as a free body under semi-implicit Euler: u_n = -g dt^2 n (n+1) / 2.
  const int n = 40;
  const double dt = 1e-3, expected = -9.81 * dt * dt * n * (n + 1) / 2;
  const double fall = report["probes"]["free_end"]["displacement"][2];
  EXPECT_NEAR(fall / expected, 1.0, 1e-3);
  // The clamped part is a stiff cantilever (static sag ~4e-6 at its end, period ~3 ms): it
  // stays within twice its static sag, a thousandth of the free piece's fall.
  const double held = report["probes"]["before_cut"]["displacement"][2];
  EXPECT_LT(std::abs(held), 1e-2 * std::abs(expected));
  EXPECT_TRUE(fs::exists(dir / "out" / "textures" / "enrichment.vdb"));
}

TEST(CliCuts, SaveTexturesWithoutCutsSaysSoInsteadOfWritingNothingSilently) {
  const fs::path dir = fresh_dir("textures_without_cuts");
  nlohmann::json scene = cut_strip();
  scene.erase("cuts");
  scene.erase("enrichment");
  scene["analysis"]["steps"] = 2;
  const Result r = run_scene(scene, dir, "--save-textures --no-render");
  ASSERT_EQ(r.exit_code, 0) << r.stderr_text;
  EXPECT_NE(r.stderr_text.find("--save-textures writes the textures of cuts, and the scene has none"),
            std::string::npos)
      << r.stderr_text;
  EXPECT_FALSE(fs::exists(dir / "out" / "textures"));
  ASSERT_TRUE(fs::exists(dir / "out" / "report.json"));
  EXPECT_EQ(report_of(dir)["reserved_step_memory_bytes"], 0);  // no texel fields to reserve for
}

TEST(CliCuts, ProgressiveCutChangesTheBasisEveryStepAndReportsItsStages) {
  const fs::path dir = fresh_dir("progressive");
  nlohmann::json scene = cut_strip();
  scene["analysis"]["steps"] = 12;
  scene["cuts"] = nlohmann::json::parse(R"([{"points": [[0.625, 0, 0], [0.625, 0.25, 0]], "start_time": 0.001, "speed": 25}])");
  const Result r = run_scene(scene, dir, "--no-render");
  ASSERT_EQ(r.exit_code, 0) << r.stderr_text;
  const nlohmann::json report = report_of(dir);
  EXPECT_EQ(report["counts"]["enrichments"], 1);
  // The set-up reserved memory for the first steps by default (dgtex/step_memory.h).
  EXPECT_GT(report["reserved_step_memory_bytes"].get<std::int64_t>(), 0);
  EXPECT_LE(report["reserved_step_memory_bytes"].get<std::int64_t>(), std::int64_t{512} << 20);
  // The cut grows 0.025 per step (1 texel of the 0.25-wide element at T = 32 is 0.0078):
  // the basis changes on every step while it grows (steps 2..11), then it is complete.
  EXPECT_GE(report["counts"]["basis_changes"].get<int>(), 9);
  EXPECT_LE(report["counts"]["basis_changes"].get<int>(), 12);
  const auto& t = report["timings_ms"];
  EXPECT_EQ(t["enrichment"]["calls"], 13);  // time 0 and every step
  EXPECT_EQ(t["projection"]["calls"], report["counts"]["basis_changes"]);
  EXPECT_EQ(t["assembly"]["calls"], 12);
  EXPECT_GE(t["enrichment"]["max"].get<double>(), t["enrichment"]["mean"].get<double>());
  const double fall = report["probes"]["free_end"]["displacement"][2];
  EXPECT_TRUE(std::isfinite(fall));
  EXPECT_LT(fall, 0.0);
}

TEST(CliCuts, CutOffTheSurfaceIsAOneLineErrorWithNoOutput) {
  const fs::path dir = fresh_dir("error");
  nlohmann::json scene = cut_strip();
  scene["analysis"] = {{"type", "static"}};
  scene["cuts"] = nlohmann::json::parse(R"([{"points": [[0.5, 0.1, 0], [0.5, 0.2, 3]]}])");
  const Result r = run_scene(scene, dir);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.stderr_text.find("cuts[0].points[1]"), std::string::npos) << r.stderr_text;
  EXPECT_EQ(std::count(r.stderr_text.begin(), r.stderr_text.end(), '\n'), 1) << r.stderr_text;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

}  // namespace
