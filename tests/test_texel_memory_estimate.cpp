// A scene whose enrichment cannot fit in memory is refused before its first texel field is
// allocated (dgtex/texel_memory_estimate.h): fracture.json at T = 4096 would need hundreds
// of GB, and the system killed such a run minutes in. The footprints the bound counts come
// from the traced cuts and creases alone and are checked against the fields they build.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "address_space_support.h"
#include "cgroup_memory.h"
#include "dgtex/crease_enrichment.h"
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

// fracture.json's cuts as its update built them at T = 32 until session 81 (6 segments
// over 284 element regions; tri6, direct solves), at another resolution.
TexelFields fracture_like(int resolution) {
  TexelFields fields;
  fields.type = ElementType::tri6;
  fields.resolution = resolution;
  fields.graph_solves = true;
  fields.cuts = {6, 284};
  return fields;
}

TEST(TexelMemoryEstimate, LowerBoundIsBytesPerActiveTexelOfEveryFieldsRegion) {
  TexelFields fields = fracture_like(256);
  // tri6: the texels with i + j <= T - 1
  EXPECT_EQ(texel_memory_lower_bound(fields), 284LL * 256 * 257 / 2 * kGraphSolveBytesPerTexel);
  fields.type = ElementType::quad8;
  EXPECT_EQ(texel_memory_lower_bound(fields), 284LL * 256 * 256 * kGraphSolveBytesPerTexel);
  fields.graph_solves = false;
  EXPECT_EQ(texel_memory_lower_bound(fields), 284LL * 256 * 256 * kFieldBytesPerTexel);
  fields.creases = {1, 24};  // creases count as fields without a solve
  EXPECT_EQ(texel_memory_lower_bound(fields), (284LL + 24) * 256 * 256 * kFieldBytesPerTexel);
  fields.resolution = 4096;  // no 32-bit overflow
  EXPECT_EQ(texel_memory_lower_bound(fields), (284LL + 24) * 4096 * 4096 * kFieldBytesPerTexel);
}

// The counts come from the paths alone; the update's own regions (its functions' Omega_i)
// can hold an element less where a path grazes one (slinky 48 against 47), and a segment
// whose every texel edge lies on other segments' paths has no function (fracture's last
// 0.004 of cut 2, after its small loop, 3 texel edges: 274 against 261 since session 81,
// 290 against 271 in sessions 73-80, 290 against 284 before): an over-count of at most a
// few per cent, inside the bounds' margins (64 bytes a texel against >= 84 measured; on
// tri6, 160 against >= 192).
TEST(TexelMemoryEstimate, FootprintMatchesTheRegionsOfTheWholeCuts) {
  for (const std::string name : {"chad", "spiral6", "slinky", "fracture"}) {
    SCOPED_TRACE(name);
    const Scene scene = example_scene(name);
    const Mesh mesh = build_scene_mesh(scene);
    CutManager cuts(mesh, build_topology(mesh), scene.cuts, scene.enrichment);
    const TexelFootprint footprint = cuts.full_footprint();
    cuts.update(1e9);  // every cut whole
    ASSERT_TRUE(cuts.complete());
    std::int64_t region_elements = 0;
    for (const EnrichmentFunction& function : cuts.functions())
      region_elements += static_cast<std::int64_t>(function.elements.size());
    const int segments_without_function = name == "fracture" ? 1 : 0;
    EXPECT_EQ(footprint.fields, cuts.total_segments());
    EXPECT_EQ(static_cast<int>(cuts.functions().size()), footprint.fields - segments_without_function);
    EXPECT_GE(footprint.region_elements, region_elements);
    EXPECT_LE(footprint.region_elements, region_elements * (segments_without_function ? 108 : 105) / 100);
  }
}

TEST(TexelMemoryEstimate, CreaseFootprintCountsTheTilesOfItsFunctions) {
  const Scene scene = example_scene("crease");
  Mesh mesh = build_scene_mesh(scene);
  Scene finer = scene;  // 8 x 8 elements, the crease inside a column of them
  finer.mesh.divisions = {8, 8};
  finer.creases[0].points = {{0.45, 0, 0}, {0.45, 1, 0}};
  for (const Scene& s : {scene, finer}) {
    mesh = build_scene_mesh(s);
    const std::vector<TracedCrease> traced = trace_creases(mesh, build_topology(mesh), s.creases, 32);
    const TexelFootprint footprint = crease_footprint(traced);
    const std::vector<EnrichmentFunction> functions = build_crease_functions(mesh, traced);
    ASSERT_EQ(footprint.fields, static_cast<int>(functions.size()));
    EXPECT_EQ(footprint.region_elements, static_cast<std::int64_t>(functions[0].elements.size()));
  }
  EXPECT_EQ(crease_footprint(trace_creases(mesh, build_topology(mesh), finer.creases, 32)).region_elements, 24);  // 3 columns of 8
}

TEST(TexelMemoryEstimate, TooLittleMemoryIsASceneErrorNamingTheResolution) {
  TexelFields fields = fracture_like(4096);
  const std::int64_t needed = texel_memory_lower_bound(fields);
  EXPECT_NO_THROW(check_texel_memory(fields, needed, "f.json"));
  EXPECT_NO_THROW(check_texel_memory(fields, -1, "f.json"));  // unknown: no check

  // 1 GiB: T = 256 needs 284 x 32896 x 160 B = 1.39 GiB, T = 128 0.35 GiB.
  try {
    check_texel_memory(fields, std::int64_t{1} << 30, "f.json");
    FAIL() << "no SceneError";
  } catch (const SceneError& e) {
    EXPECT_EQ(e.json_path(), "enrichment.texture_resolution");
    EXPECT_EQ(std::string(e.what()),
              "f.json: enrichment.texture_resolution: the texel fields of 6 cut segments (284 element regions, 160 "
              "bytes a texel with texel-graph Laplace solves) at 4096 x 4096 texels an element need at least 355.1 GiB, "
              "more than the 1.0 GiB of memory available, got 4096; expected 128 or less (the most that could fit on "
              "this machine)");
  }
  fields.type = ElementType::quad8;
  fields.graph_solves = false;
  fields.creases = {1, 24};
  const std::string none = message_of<SceneError>([&] { check_texel_memory(fields, 1000, "f.json"); });
  EXPECT_NE(none.find("the texel fields of 6 cut segments (284 element regions, 64 bytes a texel with tile multigrid "
                      "Laplace solves) and 1 crease (24 element regions, 64 bytes a texel) at 4096 x 4096"),
            std::string::npos)
      << none;
  EXPECT_NE(none.find("got 4096; no texture_resolution fits on this machine; fewer or shorter cuts or creases"),
            std::string::npos)
      << none;
}

// Every memory message writes sizes alike, in the binary units of DGTEX_MEMORY_LIMIT_MB.
TEST(TexelMemoryEstimate, MemorySizesAreWholeMiBBelowAGiBAndGiBAbove) {
  constexpr std::int64_t mib = std::int64_t{1} << 20;
  EXPECT_EQ(memory_size_text(0), "0 MiB");
  EXPECT_EQ(memory_size_text(645 * mib + 1), "645 MiB");
  EXPECT_EQ(memory_size_text(1024 * mib - 1), "1023 MiB");
  EXPECT_EQ(memory_size_text(1024 * mib), "1.0 GiB");
  EXPECT_EQ(memory_size_text(381300000000), "355.1 GiB");
}

// Between half the memory and all of it the scene runs, with a caution first (runs measured
// up to 4x the bound): fracture at T = 1024 passed the check and was still killed.
TEST(TexelMemoryEstimate, ACautionAboveHalfTheMemoryAvailable) {
  const TexelFields fields = fracture_like(1024);
  const std::int64_t needed = texel_memory_lower_bound(fields);  // 22.2 GiB
  const std::int64_t available = std::int64_t{25} << 30;
  EXPECT_EQ(texel_memory_caution(fields, 2 * needed), "");
  EXPECT_EQ(texel_memory_caution(fields, -1), "");
  EXPECT_EQ(texel_memory_caution(fields, needed - 1), "");  // refused by check_texel_memory instead
  EXPECT_EQ(texel_memory_caution(fields, available),
            "enrichment.texture_resolution 1024: the texel fields need at least 22.2 GiB of the 25.0 GiB of memory "
            "available, and runs measured 1.3-4x that bound; the run may be killed for memory (a lower "
            "texture_resolution is safer)");
  EXPECT_NO_THROW(check_texel_memory(fields, available, "f.json"));  // a caution, not a refusal
}

// The fields SceneRun checks, handed to SceneRunOptions::before_texel_fields (where
// `dgtex run` prints its caution) with the memory available: fracture's cuts on tri6
// (direct solves), a crease on quad8, no call for a scene without either.
TexelFields fields_seen_by_scene_run(const std::string& name, int& calls) {
  TexelFields seen;
  SceneRunOptions options;
  options.before_texel_fields = [&](const TexelFields& fields, std::int64_t available) {
    seen = fields;
    ++calls;
    if (available >= 0) {
      EXPECT_LE(texel_memory_lower_bound(fields), available);  // called after the check passed
    }
  };
  SceneRun run(example_scene(name), options);
  return seen;
}

TEST(TexelMemoryEstimate, SceneRunHandsItsFieldsToTheCallerBeforeAllocatingThem) {
  int calls = 0;
  const TexelFields fracture = fields_seen_by_scene_run("fracture", calls);
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(fracture.type, ElementType::tri6);
  EXPECT_EQ(fracture.resolution, 32);
  EXPECT_TRUE(fracture.graph_solves);
  EXPECT_EQ(fracture.cuts.fields, 5);  // 6 and 290 until session 81 (cut 1 split in two)
  EXPECT_EQ(fracture.cuts.region_elements, 274);
  EXPECT_EQ(fracture.creases.fields, 0);
  const TexelFields crease = fields_seen_by_scene_run("crease", calls);
  EXPECT_EQ(calls, 2);
  EXPECT_FALSE(crease.graph_solves);
  EXPECT_EQ(crease.cuts.fields, 0);
  EXPECT_EQ(crease.creases.fields, 1);
  EXPECT_EQ(crease.creases.region_elements, 1);
  EXPECT_EQ(texel_memory_lower_bound(fields_seen_by_scene_run("cylinder_buckling", calls)), 0);
  EXPECT_EQ(calls, 2);
}

TEST(TexelMemoryEstimate, AvailableMemoryIsPositiveAndAtMostWhatTheMachineHas) {
  std::ifstream meminfo("/proc/meminfo");
  if (!meminfo) GTEST_SKIP() << "no /proc/meminfo";
  std::string key, unit;
  long long kib = 0, total = 0;
  while (meminfo >> key >> kib) {
    if (key == "MemTotal:" || key == "SwapTotal:") total += kib * 1024;
    std::getline(meminfo, unit);
  }
  const std::int64_t available = available_memory_bytes();
  EXPECT_GT(available, 0);
  EXPECT_LE(available, total);
}

// A container's limit from its cgroup's files (written here in a temporary folder): the
// limit less the usage, 0 past it, nothing for v2's "max", v1's "no limit" near 2^63, or a
// missing or unreadable file. And the machine's own: what is available lies within the room
// its cgroup leaves, where it has a limit.
TEST(TexelMemoryEstimate, AContainersLimitIsTheRoomItsCgroupLeaves) {
  const std::string dir = ::testing::TempDir() + "dgtex_cgroup_" + std::to_string(::getpid()) + "_";
  auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir + name) << text;
    return dir + name;
  };
  const std::string limit = write("limit", "1073741824\n"), usage = write("usage", "314572800\n");
  EXPECT_EQ(detail::cgroup_memory_left(limit, usage), 1073741824 - 314572800);
  EXPECT_EQ(detail::cgroup_memory_left(write("small_limit", "1000\n"), usage), 0);  // over it: no room
  EXPECT_EQ(detail::cgroup_memory_left(write("v2_none", "max\n"), usage), -1);
  EXPECT_EQ(detail::cgroup_memory_left(write("v1_none", "9223372036854771712\n"), usage), -1);
  EXPECT_EQ(detail::cgroup_memory_left(dir + "missing", usage), -1);
  EXPECT_EQ(detail::cgroup_memory_left(limit, dir + "missing"), -1);
  EXPECT_EQ(detail::cgroup_memory_left(limit, write("garbage", "lots\n")), -1);
  for (const char* name : {"limit", "usage", "small_limit", "v2_none", "v1_none", "garbage"}) std::remove((dir + name).c_str());

  for (const auto& [limit_file, usage_file] :
       {std::pair{detail::kCgroupV2LimitFile, detail::kCgroupV2UsageFile},
        std::pair{detail::kCgroupV1LimitFile, detail::kCgroupV1UsageFile}}) {
    // Read on both sides, as other processes of the group (tests beside this one) move its
    // usage; a missing cap would show as the host's memory, gigabytes above.
    const std::int64_t before = detail::cgroup_memory_left(limit_file, usage_file);
    const std::int64_t available = available_memory_bytes();
    const std::int64_t after = detail::cgroup_memory_left(limit_file, usage_file);
    if (before >= 0 && after >= 0) {
      EXPECT_LE(available, std::max(before, after) + (std::int64_t{256} << 20)) << limit_file;
    }
  }
}

// DGTEX_MEMORY_LIMIT_MB caps what the memory checks may use (one process per test: the
// environment is this test's own).
TEST(TexelMemoryEstimate, TheEnvironmentsLimitCapsTheMemoryAvailable) {
  ::setenv("DGTEX_MEMORY_LIMIT_MB", "64", 1);
  const std::int64_t capped = available_memory_bytes();
  EXPECT_GT(capped, 0);
  EXPECT_LE(capped, std::int64_t{64} << 20);
  TexelFields fields;  // fracture-like: 5 segments over 280 tri6 elements at T = 256
  fields.type = ElementType::tri6;
  fields.resolution = 256;
  fields.graph_solves = true;
  fields.cuts = {5, 280};
  EXPECT_THROW(check_texel_memory(fields, capped, "fracture.json"), SceneError);
  for (const char* bad : {"abc", "0", "-5", "12x", "99999999999999999999"}) {
    ::setenv("DGTEX_MEMORY_LIMIT_MB", bad, 1);
    const std::string what = test::message_of<std::invalid_argument>([] { available_memory_bytes(); });
    EXPECT_NE(what.find(std::string("DGTEX_MEMORY_LIMIT_MB = '") + bad + "'"), std::string::npos) << what;
  }
  ::setenv("DGTEX_MEMORY_LIMIT_MB", "", 1);  // empty: as unset
  EXPECT_GT(available_memory_bytes(), capped);
  ::unsetenv("DGTEX_MEMORY_LIMIT_MB");
}

// Under `ulimit -v` allocations fail once the address space is used, whatever the machine
// has free: the memory available is at most what the limit leaves (the checks read the
// machine's memory alone, and a scene past the limit ended in std::bad_alloc).
TEST(TexelMemoryEstimate, TheAddressSpaceLimitCapsTheMemoryAvailable) {
  const std::int64_t room = std::int64_t{256} << 20;
  test::ScopedAddressSpaceLimit limit(room);
  if (!limit.why_not().empty()) GTEST_SKIP() << limit.why_not();
  const std::int64_t available = available_memory_bytes();
  limit.restore();  // before any assertion can fail
  EXPECT_LE(available, room);
  EXPECT_GT(available, room / 2);  // the process grew by less than 128 MiB between the two reads
  EXPECT_GT(available_memory_bytes(), room) << "the machine should have more than 256 MiB free";
}

// The whole path: fracture.json at T = 4096 through SceneRun, refused in the set-up before
// any tile exists (this test would otherwise take the machine's memory).
TEST(TexelMemoryEstimate, SceneRunRefusesCutsThatCannotFitBeforeItsFirstUpdate) {
  Scene scene = example_scene("fracture");
  scene.enrichment.texture_resolution = 4096;
  const Mesh mesh = build_scene_mesh(scene);
  const CutManager cuts(mesh, build_topology(mesh), scene.cuts, scene.enrichment);
  TexelFields fields = fracture_like(4096);
  fields.cuts = cuts.full_footprint();
  const std::int64_t needed = texel_memory_lower_bound(fields);
  if (available_memory_bytes() >= needed) GTEST_SKIP() << "this machine has the memory for T = 4096";
  const std::string message = message_of<SceneError>([&] { SceneRun run(scene); });
  EXPECT_NE(message.find("fracture.json: enrichment.texture_resolution: the texel fields of " +
                         std::to_string(fields.cuts.fields) + " cut segments"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("got 4096; expected"), std::string::npos) << message;
}

// The same for a crease (no cuts): 16 x 16 elements, the crease through a column of 16,
// 48 regions, at least 48.0 GiB at T = 4096.
TEST(TexelMemoryEstimate, SceneRunRefusesCreasesThatCannotFitBeforeBuildingThem) {
  Scene scene = example_scene("crease");
  scene.mesh.divisions = {16, 16};
  scene.creases[0].points = {{0.47, 0, 0}, {0.47, 1, 0}};
  scene.enrichment.texture_resolution = 4096;
  TexelFields fields;
  fields.resolution = 4096;
  fields.creases = {1, 48};
  if (available_memory_bytes() >= texel_memory_lower_bound(fields)) GTEST_SKIP() << "this machine has the memory";
  const std::string message = message_of<SceneError>([&] { SceneRun run(scene); });
  EXPECT_NE(message.find("crease.json: enrichment.texture_resolution: the texel fields of 1 crease (48 element "
                         "regions, 64 bytes a texel) at 4096 x 4096 texels an element need at least 48.0 GiB"),
            std::string::npos)
      << message;
}

}  // namespace
