// SceneRun's overlapped cut updates (dgtex/scene_run.h): the next step's cut update runs
// beside the current step, so the state must be bitwise that of the plain order after every
// step, with 1 or 2 threads, for a progressive cut that changes the basis every step
// (spiral6's first segment). After the scene's last step no update is left running
// ahead: the cut manager's functions are those of the plain run's last step.
#include <gtest/gtest.h>

#include <omp.h>

#include <string>
#include <vector>

#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"

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

Trace run(const Scene& scene, bool overlap, int threads) {
  const int saved = omp_get_max_threads();
  omp_set_num_threads(threads);
  SceneRunOptions options;
  options.overlap_cut_updates = overlap;
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
  omp_set_num_threads(saved);
  return trace;
}

}  // namespace

TEST(SceneRunOverlap, OverlappedCutUpdatesGiveThePlainStateAfterEveryStep) {
  const Scene scene = short_spiral6(12);
  const Trace plain = run(scene, false, 2);
  ASSERT_EQ(plain.displacement.size(), 12u);
  EXPECT_GE(plain.basis_changes, 10);  // the cut advances (nearly) every step
  for (int threads : {2, 1}) {
    SCOPED_TRACE("threads " + std::to_string(threads));
    const Trace overlapped = run(scene, true, threads);
    EXPECT_EQ(overlapped.basis_changes, plain.basis_changes);
    ASSERT_EQ(overlapped.displacement.size(), plain.displacement.size());
    for (std::size_t s = 0; s < plain.displacement.size(); ++s)
      EXPECT_EQ(overlapped.displacement[s], plain.displacement[s]) << "step " << s + 1;
    // Not one step ahead after the scene's last step.
    EXPECT_EQ(overlapped.last_functions, plain.last_functions);
  }
}
