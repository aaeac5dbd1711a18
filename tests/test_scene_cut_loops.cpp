// Closed loops cut out of a plate, run as scenes: the piece inside a loop falls freely
// under gravity while the clamped plate around it sags. A loop given as a closed polyline
// and the loop a self-crossing cut makes between its two passes are the same cut: until
// session 72 the self-crossing one kept the loop and the tail before it in one enrichment
// function, which varies outside the loop, and the inside stayed attached (-0.026 instead
// of the free fall's -0.505 after a second).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "dgtex/scene.h"
#include "dgtex/scene_run.h"
#include "scene_in_code_support.h"
#include "scene_run_displacement_support.h"

namespace {

using namespace dgtex;

// A 1 x 1 plate of 2 x 2 quad8 clamped at x = 0, under gravity g = 1, for 100 steps of 10
// ms, cut along `points` (T = 16); the displacement at `probe` at the end.
Vec3 displacement_after_a_second(const std::vector<Vec3>& points, const Vec3& probe) {
  Scene scene = test::square_plate_built_in_code(ElementType::quad8, 1e9);
  Load gravity;
  gravity.acceleration = {0, 0, -1};
  scene.loads.push_back(gravity);
  scene.analysis.type = Analysis::Type::dynamic;
  scene.analysis.time_step = 0.01;
  scene.analysis.steps = 100;
  scene.analysis.corotational = true;
  Cut cut;
  cut.points = points;
  scene.cuts.push_back(cut);
  SceneRun run(scene);
  while (run.steps_taken() < scene.analysis.steps) run.step();
  return test::displacement_at(run, probe);
}

// Semi-implicit Euler's fall after n steps of dt from rest: g dt^2 n (n + 1) / 2.
constexpr double kFreeFall = -1.0 * 0.01 * 0.01 * 100 * 101 / 2;

TEST(SceneCutLoops, TheInsideOfASelfCrossingCutsLoopFallsFreely) {
  // A -> B -> C -> D crosses itself at X = (0.725, 0.75): the loop X -> B -> C -> X lies in
  // element 3, away from its nodes.
  const Vec3 a{0.55, 0.6, 0}, b{0.9, 0.9, 0}, c{0.9, 0.6, 0}, d{0.55, 0.9, 0}, x{0.725, 0.75, 0};
  const Vec3 inside{0.85, 0.75, 0};
  for (const auto& [name, points] : {std::pair<std::string, std::vector<Vec3>>{"closed polyline", {x, b, c, x}},
                                     {"self-crossing cut", {a, b, c, d}}}) {
    SCOPED_TRACE(name);
    const Vec3 u = displacement_after_a_second(points, inside);
    std::printf("%s: the loop's inside moved [%.1e, %.1e, %.6f] (free fall %.6f, off by %.1e)\n", name.c_str(),
                u[0], u[1], u[2], kFreeFall, std::abs(u[2] - kFreeFall) / std::abs(kFreeFall));
    EXPECT_NEAR(u[2], kFreeFall, 1e-9 * std::abs(kFreeFall));  // measured 1.0e-13 off (both)
    EXPECT_LT(std::hypot(u[0], u[1]), 1e-9);
  }
}

}  // namespace
