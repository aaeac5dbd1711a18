// ShellModel's assembly writes its local blocks into arrays that are not zero-filled
// (dgtex/scratch_array.h): the kernels must write every entry that the assembly reads. With
// the poisoning test hook on, every such array starts full of NaN; scene runs must then give
// bitwise the states of runs without it (where the arrays hold whatever the heap left).
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <string>
#include <vector>

#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"
#include "dgtex/scratch_array.h"
#include "multigrid_buffer.h"
#include "thread_count_support.h"

using namespace dgtex;

namespace {

TEST(ScratchArray, KeepsItsEntriesWhileTheSizeStaysAndIsPoisonedUnderTheHook) {
  detail::ScratchArray a;
  EXPECT_EQ(a.resize(0), nullptr);
  EXPECT_EQ(a.size(), 0u);
  const std::size_t n = 40000;
  double* p = a.resize(n);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(a.size(), n);
  for (std::size_t k = 0; k < n; ++k) p[k] = 1.5;
  EXPECT_EQ(a.resize(n), p);  // the same size keeps the memory and its entries
  EXPECT_EQ(p[n - 1], 1.5);
  a.clear();
  EXPECT_EQ(a.data(), nullptr);
  const detail::PoisonUnzeroedBlocksScope poison;
  const double* q = a.resize(n + 1);
  int nan = 0;
  for (std::size_t k = 0; k <= n; ++k) nan += std::isnan(q[k]);
  EXPECT_EQ(nan, static_cast<int>(n + 1));  // the test hook reaches the arrays
}

// An example scene, or "cut_along_edges": fracture's mesh cut once along the element edges
// at x = 0.5, so that the enriched edges there keep no quadrature point.
Scene scene_named(const std::string& name) {
  const std::string dir = std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/";
  if (name != "cut_along_edges") return load_scene(dir + name + ".json");
  Scene scene = load_scene(dir + "fracture.json");
  Cut cut;
  cut.points = {{0.5, 1.0, 0.0}, {0.5, 0.0, 0.0}};
  scene.cuts = {cut};
  return scene;
}

// The states after each of `steps` steps; a static scene's one solution.
std::vector<std::vector<double>> run(const std::string& name, int steps) {
  Scene scene = scene_named(name);
  if (!scene.analysis.is_dynamic()) {
    SceneRun run(scene);
    run.solve_static();
    return {run.displacement()};
  }
  scene.analysis.steps = steps;
  SceneRun run(scene);
  std::vector<std::vector<double>> states;
  for (int s = 0; s < steps; ++s) {
    run.step();
    states.push_back(run.displacement());
  }
  return states;
}

class ShellAssemblyScratchBlocks : public ::testing::TestWithParam<const char*> {};

TEST_P(ShellAssemblyScratchBlocks, PoisonedBlocksGiveTheSameStates) {
  // spiral6: a new model nearly every step; fracture: tri6, enriched blocks padded to 20
  // basis functions; slinky: quad8, non-planar; thickness_texture: material-textured
  // elements (static: its solution); cylinder_buckling: the plain model (cached rest rows,
  // edge factors); cut_along_edges: enriched edges without points, whose blocks are written
  // as 0.
  const std::string name = GetParam();
  const int steps = name == "spiral6" ? 8 : 2;
  const test::ThreadCountGuard set_threads(2);
  const std::vector<std::vector<double>> leftovers = run(name, steps);
  std::vector<std::vector<double>> poisoned;
  {
    const detail::PoisonUnzeroedBlocksScope poison;
    poisoned = run(name, steps);
  }
  ASSERT_EQ(poisoned.size(), leftovers.size());
  for (std::size_t s = 0; s < poisoned.size(); ++s) {
    for (double v : poisoned[s]) ASSERT_TRUE(std::isfinite(v)) << "step " << s + 1;
    EXPECT_EQ(poisoned[s], leftovers[s]) << "step " << s + 1;
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, ShellAssemblyScratchBlocks,
                         ::testing::Values("spiral6", "fracture", "slinky", "thickness_texture", "cylinder_buckling",
                                           "cut_along_edges"));

}  // namespace
