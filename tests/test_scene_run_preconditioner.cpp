// SceneRun carries the preconditioner pattern across basis changes (dgtex/scene_run.h):
// once a simulation's element-local preconditioner has failed, the simulations of later
// bases factorise the whole pattern from their first solve instead of trying (and failing)
// again. The fracture scene's element-local matrix is not positive definite; with its cuts
// growing (100 m/s: a basis change every step) each new basis used to waste an
// element-local factorisation. The solves must still meet the tolerance.
#include <gtest/gtest.h>

#include <string>

#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"

using namespace dgtex;

TEST(SceneRunPreconditioner, AFallbackToTheWholePatternCarriesOverToLaterBases) {
  Scene scene = load_scene(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/fracture.json");
  scene.analysis.steps = 8;
  for (Cut& cut : scene.cuts) cut.speed = 100.0;
  SceneRun run(scene);
  for (int s = 0; s < scene.analysis.steps; ++s) {
    run.step();
    EXPECT_LE(run.simulation().solver_statistics().last_relative_residual, FactorReuseOptions{}.relative_tolerance)
        << "step " << s + 1;
  }
  EXPECT_GE(run.basis_changes(), 7);
  // Before: a fallback at every basis change.
  EXPECT_EQ(run.solver_statistics().element_local_fallbacks, 1);
}
