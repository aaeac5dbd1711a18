// SceneRun's overlapped cut updates (dgtex/scene_run.h): the next step's cut update runs
// beside the current step, so the state must be bitwise that of the plain order after every
// step, with 1, 2 or 4 threads (the update's own team balanced or fixed), for a progressive cut that changes the basis every step
// (spiral6's first segment). After the scene's last step no update is left running
// ahead: the cut manager's functions are those of the plain run's last step.
#include <gtest/gtest.h>

#include <omp.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"
#include "thread_count_support.h"

using namespace dgtex;

namespace {

const std::string kScenes = std::string(DGTEX_SOURCE_DIR) + "/examples/scenes";

// spiral6 cut short (analysis.steps): the last step is the scene's.
Scene short_spiral6(int steps) {
  Scene scene = load_scene(kScenes + "/spiral6.json");
  scene.analysis.steps = steps;
  return scene;
}

struct Trace {
  std::vector<std::vector<double>> displacement;  // after every step
  int basis_changes = 0;
  std::vector<double> last_functions;  // the cut manager's functions after the last step
};

Trace run(const Scene& scene, bool overlap, int threads, int cut_update_threads = 0) {
  const test::ThreadCountGuard set_threads(threads);
  SceneRunOptions options;
  options.overlap_cut_updates = overlap;
  options.cut_update_threads = cut_update_threads;
  Trace trace;
  {
    SceneRun run(scene, options);
    for (int s = 0; s < scene.analysis.steps; ++s) {
      run.step();
      trace.displacement.push_back(run.displacement());
    }
    trace.basis_changes = run.basis_changes();
    for (const EnrichmentFunction& f : run.cuts()->functions()) {
      trace.last_functions.insert(trace.last_functions.end(), f.enriched_nodes.begin(), f.enriched_nodes.end());
      for (const ElementTexture& t : f.elements)
        trace.last_functions.insert(trace.last_functions.end(), t.tile.values.begin(), t.tile.values.end());
    }
  }
  return trace;
}

}  // namespace

TEST(SceneRunOverlap, OverlappedCutUpdatesGiveThePlainStateAfterEveryStep) {
  const Scene scene = short_spiral6(12);
  const Trace plain = run(scene, false, 2);
  ASSERT_EQ(plain.displacement.size(), 12u);
  EXPECT_GE(plain.basis_changes, 10);  // the cut advances (nearly) every step
  // 4 threads: the update's team balanced step by step, and fixed at 3 (the step's loops on
  // one thread beside it).
  const struct {
    int threads, cut_update_threads;
  } cases[] = {{2, 0}, {1, 0}, {4, 0}, {4, 3}};
  for (const auto& c : cases) {
    SCOPED_TRACE("threads " + std::to_string(c.threads) + ", cut update threads " +
                 std::to_string(c.cut_update_threads));
    const Trace overlapped = run(scene, true, c.threads, c.cut_update_threads);
    EXPECT_EQ(overlapped.basis_changes, plain.basis_changes);
    ASSERT_EQ(overlapped.displacement.size(), plain.displacement.size());
    for (std::size_t s = 0; s < plain.displacement.size(); ++s)
      EXPECT_EQ(overlapped.displacement[s], plain.displacement[s]) << "step " << s + 1;
    // Not one step ahead after the scene's last step.
    EXPECT_EQ(overlapped.last_functions, plain.last_functions);
  }
}

TEST(SceneRunOverlap, ANegativeCutUpdateThreadCountIsRefusedByName) {
  SceneRunOptions options;
  options.cut_update_threads = -1;
  try {
    SceneRun run(short_spiral6(2), options);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("cut_update_threads is -1"), std::string::npos) << e.what();
  }
}
