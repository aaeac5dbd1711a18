// Thesis Fig. 5.17: a chad, cut out of a card by a circle that leaves a bridge of 2.5
// texels, hangs by its bridge and does not separate (through dgtex::SceneRun, the driver
// of `dgtex run`).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"
#include "scene_run_displacement_support.h"

using namespace dgtex;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kResolution = 64;
constexpr double kRadius = 0.25;

// One quad8 card [0, 1]^2 held on its border; the circle around (0.5, 0.5) leaves a bridge
// of 2.5 texels at the bottom (angle -pi/2).
Scene chad_scene(int steps, double bridge_texels) {
  const double gap = bridge_texels / kResolution / kRadius;  // radians
  nlohmann::json points = nlohmann::json::array();
  const int n = 160;
  for (int k = 0; k <= n; ++k) {
    const double a = -kPi / 2 + gap / 2 + (2 * kPi - gap) * k / n;
    points.push_back({0.5 + kRadius * std::cos(a), 0.5 + kRadius * std::sin(a), 0.0});
  }
  nlohmann::json scene = nlohmann::json::parse(R"({
    "mesh": {"generator": "rectangle", "size": [1, 1], "divisions": [1, 1], "element": "quad8"},
    "material": {"youngs_modulus": 1e10, "poisson_ratio": 0.3, "thickness": 0.02, "density": 1000},
    "penalty": 1,
    "boundary": [{"select": {"plane": {"normal": [1, 0, 0], "offset": 0}}, "fix": ["x", "y", "z"]},
                 {"select": {"plane": {"normal": [1, 0, 0], "offset": 1}}, "fix": ["x", "y", "z"]},
                 {"select": {"plane": {"normal": [0, 1, 0], "offset": 0}}, "fix": ["x", "y", "z"]},
                 {"select": {"plane": {"normal": [0, 1, 0], "offset": 1}}, "fix": ["x", "y", "z"]}],
    "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81]}],
    "analysis": {"type": "dynamic", "time_step": 0.002, "steps": 1, "corotational": true}
  })");
  scene["analysis"]["steps"] = steps;
  if (bridge_texels == 0) points.push_back(points[0]);  // closed: the chad comes out
  scene["cuts"] = {{{"points", points}}};
  scene["enrichment"] = {{"texture_resolution", kResolution}};
  return parse_scene(scene.dump(), "chad.json");
}

double vertical_displacement(const SceneRun& run, double x, double y) {
  return test::displacement_at(run, {x, y, 0})[2];
}

struct ChadMotion {
  double free_fall, centre, bridge_jump, cut_jump;
};

ChadMotion simulate(double bridge_texels) {
  const int steps = 40;
  const Scene scene = chad_scene(steps, bridge_texels);
  SceneRun run(scene);
  for (int s = 0; s < steps; ++s) run.step();
  EXPECT_GE(run.model().enrichments().size(), 1u);
  const double dt = scene.analysis.time_step;
  ChadMotion m;
  m.free_fall = -9.81 * dt * dt * steps * (steps + 1) / 2;
  // Just inside and outside the circle: across the bridge and across the cut opposite it.
  const double d = 1.5 / kResolution;
  m.bridge_jump = vertical_displacement(run, 0.5, 0.5 - kRadius + d) - vertical_displacement(run, 0.5, 0.5 - kRadius - d);
  m.cut_jump = vertical_displacement(run, 0.5, 0.5 + kRadius - d) - vertical_displacement(run, 0.5, 0.5 + kRadius + d);
  m.centre = vertical_displacement(run, 0.5, 0.5);
  std::printf("bridge %.1f texels: free fall %.4e, chad centre %.4e, across the bridge %.3e, across the cut %.3e\n",
              bridge_texels, m.free_fall, m.centre, m.bridge_jump, m.cut_jump);
  return m;
}

TEST(Chad, HangsByItsBridgeAndDoesNotSeparate) {
  // Without a bridge the chad is a free body: it falls at g out of the held card.
  const ChadMotion loose = simulate(0.0);
  EXPECT_NEAR(loose.centre / loose.free_fall, 1.0, 0.01);
  EXPECT_NEAR(loose.cut_jump / loose.free_fall, 1.0, 0.05);
  // A bridge of 2.5 texels (0.04 of the 1-wide card) holds it: it sags on its bridge, far
  // less than it falls without one, and the bridge stays joined (no jump there beyond the
  // bending across 3 texels; the far side of the cut opens more).
  const ChadMotion held = simulate(2.5);
  EXPECT_LT(held.centre, 0.0);
  EXPECT_GT(held.centre, 0.1 * held.free_fall);                    // measured: 0.6 %
  EXPECT_LT(std::abs(held.bridge_jump), 0.2 * std::abs(held.cut_jump));  // measured: 4 %
}

}  // namespace
