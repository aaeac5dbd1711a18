// dgtex bench scaling (dgtex/scaling_benchmark.h): kernel results do not depend on the
// thread count, independent scenes run at once in one process end where a run alone ends,
// the command writes its JSON (every family, every thread count) and its chart, and refuses
// a scene a chosen family cannot use before any family runs.
#include <gtest/gtest.h>

#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_test_support.h"
#include "dgtex/scaling_benchmark.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"
#include "dgtex/version.h"
#include "thread_count_support.h"

namespace fs = std::filesystem;
using namespace dgtex;

namespace {

const std::string kScenes = std::string(DGTEX_SOURCE_DIR) + "/examples/scenes";

using Result = test::CliResult;
using test::run_cli;

fs::path fresh_dir(const std::string& name) { return test::fresh_dir("dgtex_bench_scaling", name); }

}  // namespace

// Each family sets the thread counts it times and then gives the caller's count back (5
// here, a count none of them times).
TEST(BenchScaling, KernelResultsAreBitwiseEqualForEveryThreadCount) {
  const test::ThreadCountGuard set_threads(5);
  const std::vector<int> threads = {1, 2, 3};
  const KernelScaling polar = scale_polar_decomposition(5000, threads, 1);
  EXPECT_EQ(omp_get_max_threads(), 5) << "polar decomposition";
  EXPECT_EQ(polar.family, "polar_decomposition");
  ASSERT_EQ(polar.ms.size(), 3u);
  EXPECT_TRUE(polar.identical_across_threads);
  for (double ms : polar.ms) EXPECT_GT(ms, 0);

  const KernelScaling assembly = scale_assembly(load_scene(kScenes + "/spiral1.json"), true, threads, 1);
  EXPECT_TRUE(assembly.identical_across_threads);
  EXPECT_NE(assembly.workload.find("1 complete-cut enrichments"), std::string::npos) << assembly.workload;
  EXPECT_EQ(omp_get_max_threads(), 5) << "assembly";

  const KernelScaling steps = scale_scene_steps(load_scene(kScenes + "/spiral1.json"), 1, {1, 2});
  EXPECT_TRUE(steps.identical_across_threads);
  ASSERT_EQ(steps.ms.size(), 2u);
  EXPECT_EQ(omp_get_max_threads(), 5) << "scene steps";

  const KernelScaling enrichment = scale_enrichment_solve(load_scene(kScenes + "/spiral1.json"), {1, 2}, 1);
  ASSERT_EQ(enrichment.ms.size(), 2u);
  EXPECT_NE(enrichment.workload.find("1 solves"), std::string::npos) << enrichment.workload;
  EXPECT_EQ(omp_get_max_threads(), 5) << "enrichment solve";
  EXPECT_THROW(scale_enrichment_solve(load_scene(kScenes + "/cylinder_buckling.json"), {1}, 1), std::invalid_argument);
  EXPECT_THROW(scale_polar_decomposition(10, {0}, 1), std::invalid_argument);
}

// The factorization times the matrix the step solver factorises: the element-local pattern,
// or the whole one where the solver rules the element-local one out by the radius of the
// couplings it drops (fracture's tri6 mesh, where its matrix is not positive definite;
// `--scene fracture.json` failed there once).
TEST(BenchScaling, FactorizationTakesTheWholePatternWhereTheSolverDoes) {
  const KernelScaling cylinder = scale_factorization(load_scene(kScenes + "/cylinder_buckling.json"), {1}, 1);
  EXPECT_NE(cylinder.workload.find("M + dt^2 K (element-local)"), std::string::npos) << cylinder.workload;
  const KernelScaling fracture = scale_factorization(load_scene(kScenes + "/fracture.json"), {1, 2}, 1);
  EXPECT_NE(fracture.workload.find("M + dt^2 K (whole pattern; the element-local one drops couplings of radius 1.1)"),
            std::string::npos)
      << fracture.workload;
  ASSERT_EQ(fracture.ms.size(), 2u);
  for (double ms : fracture.ms) EXPECT_GT(ms, 0);
}

// spiral1 (a 39-unknown shell system, a one-element multigrid Laplace solve): every run,
// alone with two threads or two at once with one thread each, ends in bitwise the same
// state as a plain SceneRun.
TEST(BenchScaling, BatchMembersEndExactlyWhereARunAloneEnds) {
  const Scene scene = load_scene(kScenes + "/spiral1.json");
  const test::ThreadCountGuard set_threads(3);
  const BatchThroughput b = measure_batch_throughput(scene, 2, 2, 2);
  EXPECT_EQ(omp_get_max_threads(), 3) << "the caller's thread count, given back";
  EXPECT_EQ(b.runs, 2);
  EXPECT_GT(b.solo_ms, 0);
  EXPECT_GT(b.batch_ms, 0);
  EXPECT_TRUE(b.identical);
  EXPECT_EQ(b.max_relative_difference, 0.0);
  omp_set_num_threads(1);
  SceneRun alone(scene);
  for (int s = 0; s < 2; ++s) alone.step();
  EXPECT_EQ(b.displacement, alone.displacement());
  EXPECT_THROW(measure_batch_throughput(scene, 0, 1, 1), std::invalid_argument);
}

// The cylinder (CHOLMOD with a METIS ordering every analysis, BLAS in every factorisation)
// and chad (enrichment Laplace systems through CHOLMOD): two runs at once in one process
// end bitwise where a run alone ends. Before CHOLMOD calls were serialised
// (runtime/cholmod_lock.h) the cylinder runs differed by 1e-7 (METIS's global random
// generator) and chad runs could fail in BLAS.
TEST(BenchScaling, ConcurrentRunsWithCholmodEndExactlyWhereARunAloneEnds) {
  for (const char* name : {"cylinder_buckling", "chad"}) {
    const BatchThroughput b = measure_batch_throughput(load_scene(kScenes + "/" + name + ".json"), 2, 3, 2);
    EXPECT_TRUE(b.identical) << name;
    EXPECT_EQ(b.max_relative_difference, 0.0) << name;
  }
}

// A scene a chosen family cannot use is refused before any family runs, naming the scene
// once: a static --scene was refused only when the factorization came, after the enrichment
// solve, both assemblies and a million polar decompositions, as "dgtex bench scaling: X:
// scene 'X' is static; ...".
TEST(BenchScaling, AScenesAFamilyCannotUseIsRefusedBeforeAnyFamilyRuns) {
  const fs::path dir = fresh_dir("refused");
  const std::string plate = kScenes + "/clamped_plate.json";
  const struct {
    std::string arguments, message;
  } cases[] = {
      {"--scene " + plate, "scene '" + plate + "' is static; the factorization needs a dynamic scene"},
      {"--cut-scene " + plate, "scene '" + plate + "' has no cuts; the enrichment solve needs \"cuts\""},
      {"--families assembly --cut-scene " + plate, "scene '" + plate + "' has no cuts; the enriched assembly needs"},
      {"--families batch --batch-scenes " + kScenes + "/spiral1.json," + plate,
       "scene '" + plate + "' is static; the batch needs a dynamic scene"},
  };
  for (const auto& c : cases) {
    const Result r = run_cli("bench scaling " + c.arguments, dir);
    EXPECT_EQ(r.exit_code, 2) << c.arguments;
    // One line (no family's progress line before it), the scene named once.
    EXPECT_EQ(r.stderr_text.rfind("dgtex bench scaling: " + c.message, 0), 0u) << r.stderr_text;
    EXPECT_EQ(std::count(r.stderr_text.begin(), r.stderr_text.end(), '\n'), 1) << r.stderr_text;
  }
}

TEST(BenchScaling, CommandWritesJsonForEveryThreadCountAndAChart) {
  const fs::path dir = fresh_dir("cli");
  const fs::path json = dir / "scaling.json", chart = dir / "scaling.png";
  const Result r = run_cli("bench scaling --threads-list 1,2 --families polar_decomposition,batch --polar-count 20000 "
                           "--repeats 1 --batch-scenes " + kScenes + "/spiral1.json --batch-steps 1 --batch-runs 2 --json " +
                               json.string() + " --chart " + chart.string(),
                           dir);
  ASSERT_EQ(r.exit_code, 0) << r.stderr_text;
  std::ifstream in(json);
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["dgtex_version"], dgtex::version());
  ASSERT_EQ(j["kernels"].size(), 1u);
  EXPECT_EQ(j["kernels"][0]["family"], "polar_decomposition");
  ASSERT_EQ(j["kernels"][0]["cases"].size(), 2u);
  EXPECT_EQ(j["kernels"][0]["cases"][1]["threads"], 2);
  EXPECT_DOUBLE_EQ(j["kernels"][0]["cases"][0]["speedup"].get<double>(), 1.0);
  ASSERT_EQ(j["batch"].size(), 1u);
  EXPECT_EQ(j["batch"][0]["runs"], 2);
  EXPECT_EQ(j["batch"][0]["identical"], true);
  const double solo = j["batch"][0]["solo_scenes_per_second"], solo_ms = j["batch"][0]["solo_ms"];
  EXPECT_NEAR(solo * solo_ms, 2e3, 1e-6);  // 2 scenes in solo_ms
  // A PNG file (gnuplot is a dependency of the project).
  std::ifstream png(chart, std::ios::binary);
  char signature[4] = {};
  png.read(signature, 4);
  EXPECT_EQ(std::string(signature + 1, 3), "PNG");

  const Result bad = run_cli("bench scaling --families no_such_family", dir);
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.stderr_text.find("no_such_family"), std::string::npos) << bad.stderr_text;
}
