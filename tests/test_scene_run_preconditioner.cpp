// SceneRun and the element-local preconditioner across basis changes (dgtex/scene_run.h).
// The fracture scene's element-local matrix is not positive definite: its dropped couplings'
// radius is far beyond FactorReuseOptions::element_local_max_dropped_radius, so each basis
// factorises the whole pattern from its first solve. Tried anyway (the radius allowed
// unbounded), the first basis falls back, and the simulations of later bases take the whole
// pattern from the start instead of trying (and failing) again. With the cuts growing
// (100 m/s: a basis change every step) the solves must still meet the tolerance.
#include <gtest/gtest.h>

#include <limits>
#include <string>

#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"

using namespace dgtex;

namespace {

Scene growing_fracture() {
  Scene scene = load_scene(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/fracture.json");
  scene.analysis.steps = 8;
  for (Cut& cut : scene.cuts) cut.speed = 100.0;
  return scene;
}

void step_meeting_the_tolerance(SceneRun& run, int steps) {
  for (int s = 0; s < steps; ++s) {
    run.step();
    EXPECT_LE(run.simulation().solver_statistics().last_relative_residual, FactorReuseOptions{}.relative_tolerance)
        << "step " << s + 1;
  }
}

}  // namespace

TEST(SceneRunPreconditioner, EveryBasisOfTheFractureSceneTakesTheWholePatternWithoutTryingElementLocal) {
  const Scene scene = growing_fracture();
  SceneRun run(scene);
  step_meeting_the_tolerance(run, scene.analysis.steps);
  EXPECT_GE(run.basis_changes(), 7);
  EXPECT_EQ(run.solver_statistics().element_local_fallbacks, 0);
  EXPECT_GT(run.simulation().element_local_dropped_radius(), FactorReuseOptions{}.element_local_max_dropped_radius);
}

TEST(SceneRunPreconditioner, AFallbackToTheWholePatternCarriesOverToLaterBases) {
  const Scene scene = growing_fracture();
  SceneRunOptions options;
  options.solver.element_local_max_dropped_radius = std::numeric_limits<double>::infinity();
  SceneRun run(scene, options);
  step_meeting_the_tolerance(run, scene.analysis.steps);
  EXPECT_GE(run.basis_changes(), 7);
  // Before: a fallback at every basis change.
  EXPECT_EQ(run.solver_statistics().element_local_fallbacks, 1);
}
