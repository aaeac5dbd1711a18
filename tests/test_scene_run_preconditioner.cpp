// SceneRun carries the preconditioner pattern across basis changes (dgtex/scene_run.h):
// once a simulation's element-local preconditioner has failed, the simulations of the later
// bases factorise the whole pattern from their first solve instead of trying (and failing)
// again. chad's cut changes the basis every step and its element-local matrices are not
// positive definite: before, every other basis change wasted an element-local
// factorisation (74 fallbacks in its 150 changes, from step 77 on). The solves must still
// meet the tolerance.
#include <gtest/gtest.h>

#include <string>

#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"

using namespace dgtex;

TEST(SceneRunPreconditioner, AFallbackToTheWholePatternCarriesOverToLaterBases) {
  Scene scene = load_scene(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/chad.json");
  scene.analysis.steps = 84;  // the first fallback comes at step 77
  SceneRun run(scene);
  for (int s = 0; s < scene.analysis.steps; ++s) {
    run.step();
    EXPECT_LE(run.simulation().solver_statistics().last_relative_residual, FactorReuseOptions{}.relative_tolerance)
        << "step " << s + 1;
  }
  EXPECT_GE(run.basis_changes(), 80);
  // Before: one fallback at each basis change from step 77 on (8 here).
  EXPECT_EQ(run.solver_statistics().element_local_fallbacks, 1);
}
