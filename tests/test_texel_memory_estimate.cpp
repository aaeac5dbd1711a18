// A scene whose cut enrichment cannot fit in memory is refused before its first tile is
// allocated (dgtex/texel_memory_estimate.h): fracture.json at T = 4096 would need hundreds
// of GB, and the system killed such a run minutes in. The footprint the bound counts comes
// from the traced paths alone and is checked against the regions the update builds.
#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

#include "dgtex/cut_manager.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_model.h"
#include "dgtex/scene_run.h"
#include "dgtex/texel_memory_estimate.h"
#include "dgtex/topology.h"
#include "exception_message_support.h"

namespace {

using namespace dgtex;
using test::message_of;

Scene example_scene(const std::string& name) {
  return load_scene(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/" + name + ".json");
}

CutTexelFootprint footprint_of(int resolution, std::int64_t segment_region_elements) {
  CutTexelFootprint footprint;
  footprint.resolution = resolution;
  footprint.segment_region_elements = segment_region_elements;
  footprint.segments = 6;
  return footprint;
}

TEST(TexelMemoryEstimate, LowerBoundIsBytesPerActiveTexelOfEverySegmentsRegion) {
  const CutTexelFootprint footprint = footprint_of(256, 296);
  EXPECT_EQ(texel_memory_lower_bound(footprint, ElementType::quad8, false), 296LL * 256 * 256 * kMultigridBytesPerTexel);
  EXPECT_EQ(texel_memory_lower_bound(footprint, ElementType::quad8, true), 296LL * 256 * 256 * kDirectSolveBytesPerTexel);
  // tri6: the texels with i + j <= T - 1
  EXPECT_EQ(texel_memory_lower_bound(footprint, ElementType::tri6, true), 296LL * 256 * 257 / 2 * kDirectSolveBytesPerTexel);
  // no 32-bit overflow at the largest resolution
  EXPECT_EQ(texel_memory_lower_bound(footprint_of(4096, 296), ElementType::quad8, false),
            296LL * 4096 * 4096 * kMultigridBytesPerTexel);
}

// The counts come from the elements the paths pass through; the update's own regions
// (functions' Omega_i) may be a few elements fewer where a path only grazes an element.
TEST(TexelMemoryEstimate, FootprintMatchesTheRegionsOfTheWholeCuts) {
  for (const std::string name : {"chad", "spiral6", "slinky", "fracture"}) {
    SCOPED_TRACE(name);
    const Scene scene = example_scene(name);
    const Mesh mesh = build_scene_mesh(scene);
    CutManager cuts(mesh, build_topology(mesh), scene.cuts, scene.enrichment);
    const CutTexelFootprint footprint = cuts.full_footprint();
    cuts.update(1e9);  // every cut whole
    ASSERT_TRUE(cuts.complete());
    std::int64_t region_elements = 0;
    for (const EnrichmentFunction& function : cuts.functions())
      region_elements += static_cast<std::int64_t>(function.elements.size());
    EXPECT_EQ(footprint.resolution, scene.enrichment.texture_resolution);
    EXPECT_EQ(footprint.segments, cuts.total_segments());
    EXPECT_EQ(static_cast<int>(cuts.functions().size()), footprint.segments);  // each segment has a function here
    EXPECT_GE(footprint.segment_region_elements, region_elements);
    EXPECT_LE(footprint.segment_region_elements, region_elements * 105 / 100);
  }
}

TEST(TexelMemoryEstimate, TooLittleMemoryIsASceneErrorNamingTheResolution) {
  const CutTexelFootprint footprint = footprint_of(4096, 296);
  const std::int64_t needed = texel_memory_lower_bound(footprint, ElementType::tri6, true);
  EXPECT_NO_THROW(check_texel_memory(footprint, ElementType::tri6, true, needed, "f.json"));
  EXPECT_NO_THROW(check_texel_memory(footprint, ElementType::tri6, true, -1, "f.json"));  // unknown: no check

  // 1 GB: T = 256 needs 296 x 32896 x 160 B = 1.56 GB, T = 128 0.39 GB.
  try {
    check_texel_memory(footprint, ElementType::tri6, true, 1000000000, "f.json");
    FAIL() << "no SceneError";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.json_path(), "enrichment.texture_resolution");
    const std::string message = e.what();
    EXPECT_EQ(message.rfind("f.json: enrichment.texture_resolution: the cuts' texel fields need at least 397.4 GB "
                            "(6 cut segments over 296 element regions of 4096 x 4096 texels, 160 bytes a texel "
                            "with direct Laplace solves), more than the 1.0 GB of memory available",
                            0),
              0u)
        << message;
    EXPECT_NE(message.find("got 4096; expected 128 or less (the most that could fit on this machine)"),
              std::string::npos)
        << message;
  }
  const std::string none = message_of<SceneError>(
      [&] { check_texel_memory(footprint, ElementType::quad8, false, 1000, "f.json"); });
  EXPECT_NE(none.find("64 bytes a texel with multigrid Laplace solves"), std::string::npos) << none;
  EXPECT_NE(none.find("no texture_resolution fits on this machine; fewer or shorter cuts"), std::string::npos) << none;
}

TEST(TexelMemoryEstimate, AvailableMemoryIsPositiveAndAtMostWhatTheMachineHas) {
  std::ifstream meminfo("/proc/meminfo");
  if (!meminfo) GTEST_SKIP() << "no /proc/meminfo";
  std::string key;
  long long kib = 0, total = 0;
  std::string unit;
  while (meminfo >> key >> kib) {
    if (key == "MemTotal:" || key == "SwapTotal:") total += kib * 1024;
    std::getline(meminfo, unit);
  }
  const std::int64_t available = available_memory_bytes();
  EXPECT_GT(available, 0);
  EXPECT_LE(available, total);
}

// The whole path: fracture.json at T = 4096 through SceneRun, refused in the set-up before
// any tile exists (this test would otherwise take the machine's memory).
TEST(TexelMemoryEstimate, SceneRunRefusesCutsThatCannotFitBeforeItsFirstUpdate) {
  Scene scene = example_scene("fracture");
  scene.enrichment.texture_resolution = 4096;
  const Mesh mesh = build_scene_mesh(scene);
  const CutManager cuts(mesh, build_topology(mesh), scene.cuts, scene.enrichment);
  const std::int64_t needed = texel_memory_lower_bound(cuts.full_footprint(), mesh.type, true);
  if (available_memory_bytes() >= needed) GTEST_SKIP() << "this machine has the memory for T = 4096";
  const std::string message = message_of<SceneError>([&] { SceneRun run(scene); });
  EXPECT_NE(message.find("fracture.json: enrichment.texture_resolution: the cuts' texel fields need at least"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("got 4096; expected"), std::string::npos) << message;
}

}  // namespace
