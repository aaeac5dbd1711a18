// Known gap, kept as a disabled test until it is fixed (run it with
// --gtest_also_run_disabled_tests): two jagged cuts where the second starts at the first's
// end point (a bent crack written as two cuts; the second also crosses itself once) give
// enrichment functions that depend on each other, so the dynamic system matrix is singular
// and the run stops with "not positive definite". Each cut alone runs; the same crack as
// one polyline runs (examples/scenes/fracture.json).
#include <gtest/gtest.h>

#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"

using namespace dgtex;

namespace {

TEST(CutsKnownGaps, DISABLED_TwoCutsSharingAnEndPointRun) {
  const Scene scene = load_scene(std::string(DGTEX_SOURCE_DIR) + "/tests/data/known_gaps/cuts_sharing_an_end_point.json");
  SceneRun run(scene);
  EXPECT_NO_THROW(run.step());
}

}  // namespace
