// The cut-boundary error measurement (runtime/cut_boundary_error.cpp), the synthetic
// benchmark state (runtime/render_benchmark.cpp) and `dgtex bench render --json`.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "dgtex/cut_boundary_error.h"
#include "dgtex/deformed_shell.h"
#include "dgtex/render_benchmark.h"
#include "render_fixtures.h"

namespace dgtex {
namespace {

namespace fs = std::filesystem;

ShellRenderer& renderer() {
  static ShellRenderer instance;
  return instance;
}

TEST(RenderBench, DistanceTransformMatchesBruteForce) {
  std::mt19937 random(7);
  for (int trial = 0; trial < 6; ++trial) {
    const int width = 17 + trial * 5, height = 11 + trial * 3;
    const double density = trial == 0 ? 0.0 : 0.02 * trial;  // trial 0: no target pixel at all
    std::vector<std::uint8_t> mask(width * height);
    std::bernoulli_distribution pick(density);
    for (auto& m : mask) m = pick(random);
    if (trial == 5) mask.assign(mask.size(), 1);  // every pixel is a target
    const std::vector<double> d = squared_distance_to(mask, 1, width, height);
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        double best = std::numeric_limits<double>::max();
        for (int v = 0; v < height; ++v)
          for (int u = 0; u < width; ++u)
            if (mask[v * width + u]) best = std::min(best, double((x - u) * (x - u) + (y - v) * (y - v)));
        ASSERT_EQ(d[y * width + x], best) << "trial " << trial << " pixel " << x << ", " << y;
      }
  }
}

TEST(RenderBench, CoverageErrorOfAShiftedBoundary) {
  const int width = 40, height = 30;
  std::vector<std::uint8_t> exact(width * height, 0), rendered(width * height, 0), ignored(width * height, 0);
  for (int y = 5; y < 25; ++y)
    for (int x = 10; x < 30; ++x) exact[y * width + x] = 1;
  for (int y = 5; y < 25; ++y)
    for (int x = 13; x < 30; ++x) rendered[y * width + x] = 1;  // left edge 3 pixels late
  rendered[2 * width + 2] = 1;                                   // a stray pixel: 3^2 + 8^2 from (10, 5)
  CoverageError e = coverage_error(rendered, exact, width, height);
  EXPECT_DOUBLE_EQ(e.max_pixels, std::sqrt(73.0));
  EXPECT_EQ(e.mismatched, 3 * 20 + 1);
  ignored[2 * width + 2] = 1;
  e = coverage_error(rendered, exact, width, height, &ignored);
  // The missing pixels x = 10, 11, 12 lie 1, 2, 3 from the true background at x = 9;
  // in rows 5 and 24 the background above/below is nearer (1, 1, 1), in rows 6 and 23
  // (1, 2, 2).
  EXPECT_DOUBLE_EQ(e.max_pixels, 3.0);
  EXPECT_NEAR(e.mean_pixels, (16 * 6 + 2 * 3 + 2 * 5) / 60.0, 1e-12);
  EXPECT_EQ(coverage_error(exact, exact, width, height).max_pixels, 0.0);
  EXPECT_THROW(coverage_error(rendered, exact, width + 1, height), std::invalid_argument);
}

// The CPU truth against the staircase plate's exact coverage (render_fixtures.h), away
// from its boundaries; the renderer against the truth: within a texel.
TEST(RenderBench, ExactCoverageAndRenderedStaircaseCut) {
  const auto plate = test::staircase_cut_plate();
  RenderSettings s = test::top_view();
  const Camera camera = make_camera(plate.state, s);
  const std::vector<std::uint8_t> exact = exact_cut_coverage(plate.state, camera);
  const double a[3] = {0, 0, 0}, b[3] = {1, 0, 0};
  double ax, ay, bx, by;
  camera.project(a, ax, ay);
  camera.project(b, bx, by);
  const double pixel = 1.0 / (bx - ax);  // world units per pixel
  int checked = 0, wrong = 0;
  for (int py = 0; py < s.height; ++py)
    for (int px = 0; px < s.width; ++px) {
      const double x = (px + 0.5 - ax) * pixel, y = (ay - py - 0.5) * pixel;
      const bool inside = plate.covers(x, y);
      bool clear = true;
      for (int k = 0; k < 8 && clear; ++k)
        clear = plate.covers(x + pixel * std::cos(M_PI * k / 4), y + pixel * std::sin(M_PI * k / 4)) == inside;
      if (!clear) continue;
      ++checked;
      wrong += exact[py * s.width + px] != inside;
    }
  EXPECT_GT(checked, s.width * s.height * 9 / 10);
  EXPECT_EQ(wrong, 0);

  const double texel_pixels = (bx - ax) / plate.resolution;
  double errors[3];
  for (auto method : {RenderSettings::CutMethod::geometry_shader, RenderSettings::CutMethod::drop_triangles,
                      RenderSettings::CutMethod::kill_pixels}) {
    s.cut_method = method;
    const Image image = renderer().render(plate.state, s);
    errors[static_cast<int>(method)] =
        coverage_error(image_coverage(image, s.background), exact, s.width, s.height).max_pixels / texel_pixels;
  }
  EXPECT_LE(errors[0], 1.0);
  EXPECT_GT(errors[1], 1.0);  // dropping cut triangles of 4 texels loses more than a texel
  EXPECT_LT(errors[0], errors[1]);
}

// The benchmark state moves every point by H1 d1 + H2 d2 (render_benchmark.h): check it
// where the values are known exactly.
TEST(RenderBench, BenchmarkStateDisplacesThePiecesAsDocumented) {
  const ShellState state = render_bench_state(32);
  ASSERT_EQ(state.mesh.num_elements(), 6);
  ASSERT_EQ(state.enrichments.size(), 3u);
  const DeformedShell shell(state);
  // Left of the wavy cut everything moves by -0.05 in x, right of it by +0.05 (the top
  // right element has no enrichment, the bottom right one carries only the partial cut).
  struct Probe {
    double X[2], moved[2];
  };
  for (const Probe& p : {Probe{{0.5, 0.5}, {-0.05, 0}}, Probe{{0.5, 1.5}, {-0.05, 0}}, Probe{{1.1, 0.3}, {-0.05, 0}},
                         Probe{{1.9, 1.7}, {0.05, 0}}, Probe{{2.5, 1.5}, {0.05, 0}}}) {
    const int column = static_cast<int>(p.X[0]), row = static_cast<int>(p.X[1]);
    const int element = row * 3 + column;  // make_rectangle numbers elements row by row
    const double xi1 = 2 * (p.X[0] - column) - 1, xi2 = 2 * (p.X[1] - row) - 1;
    double x[3];
    shell.position(element, xi1, xi2, x);
    EXPECT_NEAR(x[0], p.X[0] + p.moved[0], 1e-9) << p.X[0] << ", " << p.X[1];
    EXPECT_NEAR(x[1], p.X[1] + p.moved[1], 1e-9) << p.X[0] << ", " << p.X[1];
    EXPECT_NEAR(x[2], 0.0, 1e-12);
  }
  // Right above and below the partial cut's mouth the sides are 0.05 apart across it.
  const double dir[2] = {1 / std::hypot(1.0, 0.3), -0.3 / std::hypot(1.0, 0.3)};
  const double on_cut[2] = {2.35 + 0.5 * dir[0], 0.55 + 0.5 * dir[1]};
  // 1.5 texels off the cut, so the texel there lies wholly on one side of it.
  const double n[2] = {-dir[1], dir[0]}, h = 1.5 / 32;
  double above[3], below[3];
  auto position = [&](double X, double Y, double out[3]) {
    shell.position(2, 2 * (X - 2) - 1, 2 * Y - 1, out);
  };
  position(on_cut[0] + h * n[0], on_cut[1] + h * n[1], above);
  position(on_cut[0] - h * n[0], on_cut[1] - h * n[1], below);
  const double opening = (above[0] - below[0]) * n[0] + (above[1] - below[1]) * n[1];
  // H2 = -+(1 - delta) with delta = (angle of the texel centre seen from the tip) / pi,
  // 0.016..0.044 for centres within 0.7 texel of the sampled points.
  EXPECT_NEAR(opening, 2 * h + 0.05 * 0.97, 0.05 * 0.015);
}

TEST(RenderBench, CommandWritesJsonWithAllCases) {
  const fs::path dir = fs::path(::testing::TempDir()) / "dgtex_render_bench";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const std::string command = "'" + std::string(DGTEX_CLI) +
                              "' bench render --resolution 64 --tessellations 4,8 --repeat 1"
                              " --json '" + (dir / "bench.json").string() + "' --chart '" +
                              (dir / "chart.png").string() + "' > '" + (dir / "out.txt").string() + "' 2>&1";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << std::ifstream(dir / "out.txt").rdbuf();
  std::ifstream in(dir / "bench.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_NE(j["machine"].get<std::string>().find("one-core probe"), std::string::npos) << j["machine"];
  EXPECT_EQ(j["resolution"], 64);
  EXPECT_NEAR(j["texel_pixels"].get<double>(), render_bench_texel_pixels(64, 1280, 720), 1e-12);
  const auto& cases = j["cases"];
  ASSERT_EQ(cases.size(), 7u);  // per-texel + 3 methods x 2 tessellations
  EXPECT_EQ(cases[0]["method"], "per-texel");
  EXPECT_EQ(cases[0]["tessellation"], 64);
  EXPECT_LE(cases[0]["error_texels"].get<double>(), 1.0);
  for (const auto& c : cases) {
    const int t = c["tessellation"];
    const long long submitted = c["triangles_submitted"], drawn = c["triangles_drawn"];
    EXPECT_EQ(submitted, 6LL * 2 * t * t);
    const std::string method = c["method"];
    if (method == "drop-triangles") {
      EXPECT_LT(drawn, submitted);
      EXPECT_GT(c["error_texels"].get<double>(), 1.0);
    } else if (method == "kill-pixels") {
      EXPECT_EQ(drawn, submitted);
    } else {
      EXPECT_GT(drawn, submitted);  // cut triangles are drawn once per side
    }
    EXPECT_GE(c["error_with_tip_texels"].get<double>(), c["error_texels"].get<double>());
    EXPECT_GT(c["frame_ms"].get<double>(), 0.0);
  }
  // The target: the geometry shader at tessellation 8 (1/60 of the per-texel
  // triangles) stays within a texel of the truth away from the partial cut's tip. (With
  // per-triangle side means for the extrapolation it was 1.9 texels: hairline cracks
  // between neighbouring cut triangles.)
  EXPECT_EQ(cases[2]["method"], "geometry-shader");
  EXPECT_EQ(cases[2]["tessellation"], 8);
  EXPECT_LE(cases[2]["error_texels"].get<double>(), 1.0);
  EXPECT_LE(cases[2]["triangles_drawn"].get<double>(), cases[0]["triangles_drawn"].get<double>() / 16);
  EXPECT_EQ(j["target"]["met"], true);
  // The chart is a PNG (gnuplot-nox is part of the build dependencies).
  std::ifstream chart(dir / "chart.png", std::ios::binary);
  char magic[4] = {};
  chart.read(magic, 4);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
}

}  // namespace
}  // namespace dgtex
