// End-to-end: the dgtex executable on example scenes and on bad input.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "cli_test_support.h"
#include "dgtex/texel_memory_estimate.h"
#include "dgtex/version.h"

namespace fs = std::filesystem;

namespace {

using Result = dgtex::test::CliResult;

// `dgtex run ARGS --quiet`, stderr kept (tests/cli_test_support.h).
Result run_dgtex(const std::string& args, const fs::path& workdir) {
  return dgtex::test::run_cli("run " + args + " --quiet", workdir);
}

fs::path fresh_dir(const std::string& name) { return dgtex::test::fresh_dir("dgtex_cli", name); }

TEST(CliRun, ClampedPlateSceneWritesReportWithinOnePercent) {
  const fs::path dir = fresh_dir("plate");
  const Result r = run_dgtex(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/clamped_plate.json --out " + (dir / "out").string(), dir);
  ASSERT_EQ(r.exit_code, 0) << r.stderr_text;
  std::ifstream in(dir / "out" / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["dgtex_version"], dgtex::version());  // which build wrote it
  EXPECT_EQ(report["counts"]["elements"], 256);
  EXPECT_EQ(report["counts"]["nodes"], 833);
  EXPECT_EQ(report["counts"]["dofs"], 2499);
  EXPECT_GT(report["counts"]["nonzeros"].get<long>(), 0);
  const double w = report["probes"]["center"]["displacement"][2];
  const double D = 1e6 * 1e-6 / (12 * (1 - 0.09));
  EXPECT_NEAR(w / (-0.00126532 / D), 1.0, 0.01);
  EXPECT_GT(report["timings_ms"]["solve"]["mean"].get<double>(), 0.0);  // measured, not left 0
  EXPECT_TRUE(fs::exists(dir / "out" / "deformed.vtu"));
}

TEST(CliRun, DynamicSceneWritesFramesAndIsThreadIndependent) {
  const fs::path dir = fresh_dir("dynamic");
  const std::string scene = std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/demo_cantilever.json";
  ASSERT_EQ(run_dgtex(scene + " --threads 1 --out " + (dir / "a").string(), dir).exit_code, 0);
  ASSERT_EQ(run_dgtex(scene + " --threads 2 --out " + (dir / "b").string(), dir).exit_code, 0);
  std::ifstream a(dir / "a" / "report.json"), b(dir / "b" / "report.json");
  const nlohmann::json ra = nlohmann::json::parse(a), rb = nlohmann::json::parse(b);
  EXPECT_EQ(ra["probes"]["tip"]["displacement"], rb["probes"]["tip"]["displacement"]);
  EXPECT_TRUE(fs::exists(dir / "a" / "frames" / "frame_00200.vtu"));
  EXPECT_EQ(ra["timings_ms"]["assembly"]["calls"], 200);
}

void expect_rejected(const std::string& name, const std::string& json, const std::string& fragment,
                     const std::string& environment = "") {
  const fs::path dir = fresh_dir(name);
  std::ofstream(dir / "scene.json") << json;
  const Result r = dgtex::test::run_cli("run " + (dir / "scene.json").string() + " --out " + (dir / "out").string() +
                                            " --quiet",
                                        dir, environment);
  EXPECT_EQ(r.exit_code, 2) << r.stderr_text;
  EXPECT_NE(r.stderr_text.find(fragment), std::string::npos) << r.stderr_text;
  EXPECT_EQ(std::count(r.stderr_text.begin(), r.stderr_text.end(), '\n'), 1) << r.stderr_text;
  EXPECT_FALSE(fs::exists(dir / "out" / "report.json"));
}

const char* kBase = R"({"mesh": {"generator": "rectangle", "size": [1, 1], "divisions": [2, 2], "element": "quad8"},
  "material": {"youngs_modulus": 1e6, "poisson_ratio": NU, "thickness": 0.01, "density": 1000},
  "penalty": PENALTY, BOUNDARY "loads": [{"type": "area_force", "force_per_area": [0, 0, -1]}]})";

std::string scene(const std::string& nu, const std::string& penalty, const std::string& boundary) {
  std::string s = kBase;
  s.replace(s.find("NU"), 2, nu);
  s.replace(s.find("PENALTY"), 7, penalty);
  s.replace(s.find("BOUNDARY"), 8, boundary);
  return s;
}

const char* kClampedLeft = R"("boundary": [{"select": {"plane": {"normal": [1, 0, 0], "offset": 0}}, "fix": ["x", "y", "z"], "clamp": true}],)";

TEST(CliRun, BadInputExitsWithCodeTwoAndOneLine) {
  expect_rejected("nu", scene("0.5", "1", kClampedLeft), "material.poisson_ratio");
  expect_rejected("unconstrained", scene("0.3", "1", ""), "unconstrained");
  expect_rejected("penalty", scene("0.3", "0.01", kClampedLeft), "penalty too low?");
  expect_rejected("selection",
                  scene("0.3", "1", R"("boundary": [{"select": {"plane": {"normal": [1, 0, 0], "offset": 5}}, "fix": ["z"]}],)"),
                  "boundary[0].select");
  // Rotation clusters of one texel on the accordion (35k points, 150 functions) would need
  // ~20 GB of rest sums: with 4 GiB to use (DGTEX_MEMORY_LIMIT_MB; a machine with more
  // memory would run it) refused before they are allocated, naming the key.
  nlohmann::json accordion;
  std::ifstream(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/accordion.json") >> accordion;
  accordion["enrichment"]["rotation_cluster_texels"] = 1;
  accordion["analysis"]["steps"] = 1;
  accordion.erase("render");
  expect_rejected("clusters", accordion.dump(), "enrichment.rotation_cluster_texels = 1", "DGTEX_MEMORY_LIMIT_MB=4096");
}

// A report named like another output would overwrite it (deformed.vtu) or fail to be
// written after the whole run (frames, a folder): refused before the output folder exists.
TEST(CliRun, AReportNamedLikeAnotherOutputIsRefusedBeforeTheRun) {
  for (const std::string name : {"deformed.vtu", "final.state", "frames", "textures"}) {
    nlohmann::json plate = nlohmann::json::parse(scene("0.3", "1", kClampedLeft));
    plate["output"] = {{"report", name}};
    const fs::path dir = fresh_dir("report_" + name);
    std::ofstream(dir / "scene.json") << plate.dump();
    const Result r = dgtex::test::run_cli(
        "run " + (dir / "scene.json").string() + " --out " + (dir / "out").string() + " --quiet", dir);
    EXPECT_EQ(r.exit_code, 2) << r.stderr_text;
    EXPECT_NE(r.stderr_text.find("scene.json: output.report: the name of "), std::string::npos) << r.stderr_text;
    EXPECT_NE(r.stderr_text.find("got \"" + name + "\""), std::string::npos) << r.stderr_text;
    EXPECT_EQ(std::count(r.stderr_text.begin(), r.stderr_text.end(), '\n'), 1) << r.stderr_text;
    EXPECT_FALSE(fs::exists(dir / "out")) << name;
  }
}

// A segment length below the spacing of doubles (1e-20 beside coordinates near 1) never
// advanced the segmentation: the run hung in its set-up. Shorter than a texel, a segment has
// no texels of its own.
TEST(CliRun, ACutSegmentShorterThanATexelIsRefused) {
  nlohmann::json spiral;
  std::ifstream(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/spiral1.json") >> spiral;
  spiral["enrichment"]["new_cut_length"] = 1e-20;
  spiral.erase("render");
  expect_rejected("new_cut_length", spiral.dump(),
                  "enrichment.new_cut_length: a cut segment cannot be shorter than a texel, got 1e-20; expected ");
}

// The plate's 16 x 16 quad8 elements: a model bound of 24 MiB (dgtex/model_memory_estimate.h).
// With 40 MiB to use it runs after a caution; with 20 it is refused before its mesh exists.
TEST(CliRun, AModelNearOrBeyondTheMemoryIsCautionedOrRefused) {
  const std::string plate = std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/clamped_plate.json";
  const fs::path dir = fresh_dir("model_memory");
  const Result near = dgtex::test::run_cli("run " + plate + " --out " + (dir / "near").string() + " --quiet --no-render",
                                           dir, "DGTEX_MEMORY_LIMIT_MB=40");
  EXPECT_EQ(near.exit_code, 0) << near.stderr_text;
  EXPECT_NE(near.stderr_text.find("dgtex run: warning: " + plate + ": mesh.divisions [16, 16]: the model of its 256 "
                                  "elements needs at least 24 MiB of the 40 MiB of memory available"),
            std::string::npos)
      << near.stderr_text;
  expect_rejected("model_memory_beyond", std::string(std::istreambuf_iterator<char>(std::ifstream(plate).rdbuf()), {}),
                  "mesh.divisions: 256 quad8 elements need at least 24 MiB", "DGTEX_MEMORY_LIMIT_MB=20");
}

// A run that loses definiteness after good corotated steps has diverged (chad under 3e4
// m/s^2 sideways, at its 36th step, whatever the penalty): a failed run (exit code 1) whose
// line names the step and the likely cause, not bad input blaming the penalty (exit 2).
TEST(CliRun, ADivergedCorotatedStepIsAFailedRunNamingTheStep) {
  const fs::path dir = fresh_dir("diverged");
  nlohmann::json scene =
      nlohmann::json::parse(std::ifstream(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/chad.json"));
  scene["loads"][0]["acceleration"] = {3e4, 0, 0};
  scene["analysis"]["steps"] = 60;
  scene.erase("render");
  std::ofstream(dir / "scene.json") << scene.dump();
  const Result r = run_dgtex((dir / "scene.json").string() + " --out " + (dir / "out").string(), dir);
  EXPECT_EQ(r.exit_code, 1) << r.stderr_text;
  EXPECT_NE(r.stderr_text.find(": step "), std::string::npos) << r.stderr_text;
  EXPECT_NE(r.stderr_text.find("dynamic system matrix not positive definite in the deformed state: the run has likely "
                               "diverged"),
            std::string::npos)
      << r.stderr_text;
  EXPECT_EQ(r.stderr_text.find("(penalty too low?)"), std::string::npos) << r.stderr_text;
}

// A penalty far above its threshold locks coarse meshes and fails nothing: the run says so
// (dgtex/penalty_caution.h) and runs; the example plate at its own 0.8 runs without it.
TEST(CliRun, APenaltyFarAboveItsThresholdIsCautioned) {
  const std::string plate = std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/clamped_plate.json";
  const fs::path dir = fresh_dir("penalty_caution");
  nlohmann::json scene;
  std::ifstream(plate) >> scene;
  scene["penalty"] = 30;
  const fs::path high = dir / "high.json";
  std::ofstream(high) << scene.dump();
  const Result cautioned = dgtex::test::run_cli("run " + high.string() + " --out " + (dir / "high").string() +
                                                " --quiet --no-render", dir);
  EXPECT_EQ(cautioned.exit_code, 0) << cautioned.stderr_text;
  EXPECT_NE(cautioned.stderr_text.find("dgtex run: warning: " + high.string() + ": penalty 30 is far above the "
                                       "definiteness threshold"),
            std::string::npos)
      << cautioned.stderr_text;
  const Result plain = dgtex::test::run_cli("run " + plate + " --out " + (dir / "plain").string() + " --quiet --no-render", dir);
  EXPECT_EQ(plain.exit_code, 0) << plain.stderr_text;
  EXPECT_EQ(plain.stderr_text, "");
}

// A linear result that turns the shell by more than kLinearRotationCautionAbove is
// cautioned (dgtex/rotation_caution.h), in statics and, at the step where it was largest, in
// linear dynamics; the same dynamics corotated is not. Both runs succeed.
TEST(CliRun, ALinearResultWithLargeRotationsIsCautioned) {
  const fs::path dir = fresh_dir("rotation_caution");
  nlohmann::json plate;
  std::ifstream(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/clamped_plate.json") >> plate;
  plate["loads"][0]["force_per_area"] = {0, 0, -1000};  // 13.8 m at the centre of the 1 m plate
  std::ofstream(dir / "plate.json") << plate.dump();
  const Result statics = dgtex::test::run_cli("run " + (dir / "plate.json").string() + " --out " +
                                              (dir / "plate").string() + " --quiet --no-render", dir);
  EXPECT_EQ(statics.exit_code, 0) << statics.stderr_text;
  EXPECT_NE(statics.stderr_text.find("dgtex run: warning: " + (dir / "plate.json").string() +
                                     ": the linear solution moves two nodes of element "),
            std::string::npos)
      << statics.stderr_text;
  EXPECT_NE(statics.stderr_text.find("\"corotational\": true"), std::string::npos) << statics.stderr_text;

  nlohmann::json cantilever;
  std::ifstream(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/demo_cantilever.json") >> cantilever;
  cantilever.erase("render");
  cantilever["loads"][0]["acceleration"] = {0, 0, -20};  // linear tip deflection ~0.6 m: ~0.8 rad
  cantilever["analysis"]["steps"] = 40;
  for (const bool corotational : {false, true}) {
    cantilever["analysis"]["corotational"] = corotational;
    const std::string name = corotational ? "corotated" : "linear";
    std::ofstream(dir / (name + ".json")) << cantilever.dump();
    const Result r = dgtex::test::run_cli("run " + (dir / (name + ".json")).string() + " --out " + (dir / name).string() +
                                          " --quiet --no-render", dir);
    EXPECT_EQ(r.exit_code, 0) << r.stderr_text;
    if (corotational) {
      EXPECT_EQ(r.stderr_text, "");
    } else {
      // Elements 9 and 19 end the 10 x 2 strip.
      const bool at_tip = r.stderr_text.find(": the linear solution moves two nodes of element 9 relative to each other "
                                             "by ") != std::string::npos ||
                          r.stderr_text.find(": the linear solution moves two nodes of element 19 relative to each other "
                                             "by ") != std::string::npos;
      EXPECT_TRUE(at_tip) << r.stderr_text;
      EXPECT_NE(r.stderr_text.find(" times their distance at step "), std::string::npos) << r.stderr_text;
    }
  }
}

// A file mesh's element type is its faces'. A declared "element" that differs was ignored
// for the mesh but judged the cuts' surface_points against its own reference element
// (quad points refused as "outside the tri6 reference element"): now the declaration is
// refused, naming the faces' type, and the points are judged on the mesh read.
TEST(CliRun, AFileMeshsDeclaredElementMustMatchItsFaces) {
  const fs::path dir = fresh_dir("file_element");
  std::ofstream(dir / "quads.obj") << "v 0 0 0\nv 0.5 0 0\nv 1 0 0\nv 0 0.5 0\nv 0.5 0.5 0\nv 1 0.5 0\nv 0 1 0\n"
                                      "v 0.5 1 0\nv 1 1 0\nf 1 2 5 4\nf 2 3 6 5\nf 4 5 8 7\nf 5 6 9 8\n";
  nlohmann::json scene = nlohmann::json::parse(R"({
    "mesh": {"file": "quads.obj", "element": "tri6"},
    "material": {"youngs_modulus": 1e6, "poisson_ratio": 0.3, "thickness": 0.01},
    "penalty": 0.8,
    "boundary": [{"select": {"plane": {"normal": [1, 0, 0], "offset": 0}}, "fix": ["x", "y", "z"], "clamp": true}],
    "loads": [{"type": "area_force", "force_per_area": [0, 0, -1]}],
    "cuts": [{"surface_points": [{"element": 3, "xi": [-0.5, -0.5]}, {"element": 3, "xi": [0.5, 0.5]}]}],
    "enrichment": {"texture_resolution": 16}})");
  for (const std::string element : {"tri6", "quad8"}) {
    scene["mesh"]["element"] = element;
    const fs::path path = dir / (element + ".json");
    std::ofstream(path) << scene.dump();
    const Result r = dgtex::test::run_cli("run " + path.string() + " --out " + (dir / element).string() +
                                          " --quiet --no-render", dir);
    if (element == "tri6") {
      EXPECT_EQ(r.exit_code, 2) << r.stderr_text;
      EXPECT_EQ(r.stderr_text, "dgtex run: " + path.string() + ": mesh.element: does not match mesh.file, whose faces "
                               "make quad8 elements, got \"tri6\"; expected \"quad8\" or no element (a file's faces "
                               "decide it)\n");
      EXPECT_FALSE(fs::exists(dir / element));
    } else {
      EXPECT_EQ(r.exit_code, 0) << r.stderr_text;
    }
  }
}

// What a run leaves in a folder an earlier run wrote: a static scene whose solve fails
// (penalty too low, exit 2) leaves it as it was; a dynamic run failing in its first step
// clears the earlier run's outputs and leaves none of its own (it had left its frame 0); a
// run with its own output.report clears the default report too; a static run without
// render writes no frames/ folder, and every report has timings_ms.render.
TEST(CliRun, AFailedRunLeavesNothingThatLooksLikeAResult) {
  const fs::path dir = fresh_dir("failed_outputs");
  const fs::path out = dir / "out";
  nlohmann::json dynamic;
  std::ifstream(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/demo_cantilever.json") >> dynamic;
  dynamic.erase("render");
  dynamic["analysis"]["steps"] = 10;
  std::ofstream(dir / "dynamic.json") << dynamic.dump();
  auto run = [&](const std::string& scene) {
    return dgtex::test::run_cli("run " + (dir / scene).string() + " --out " + out.string() + " --quiet --no-render", dir);
  };
  ASSERT_EQ(run("dynamic.json").exit_code, 0);
  ASSERT_TRUE(fs::exists(out / "frames" / "frame_00010.vtu"));

  nlohmann::json plate;
  std::ifstream(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/clamped_plate.json") >> plate;
  plate["mesh"]["divisions"] = {4, 4};
  plate["penalty"] = 0.2;
  std::ofstream(dir / "plate_low.json") << plate.dump();
  const Result refused = run("plate_low.json");
  EXPECT_EQ(refused.exit_code, 2) << refused.stderr_text;
  EXPECT_NE(refused.stderr_text.find("penalty too low?"), std::string::npos) << refused.stderr_text;
  EXPECT_TRUE(fs::exists(out / "report.json"));
  EXPECT_TRUE(fs::exists(out / "frames" / "frame_00010.vtu"));

  dynamic["penalty"] = 0.2;
  std::ofstream(dir / "dynamic_low.json") << dynamic.dump();
  const Result failed = run("dynamic_low.json");
  EXPECT_EQ(failed.exit_code, 2) << failed.stderr_text;
  EXPECT_FALSE(fs::exists(out / "report.json"));
  EXPECT_FALSE(fs::exists(out / "deformed.vtu"));
  EXPECT_TRUE(fs::is_empty(out / "frames"));

  ASSERT_EQ(run("dynamic.json").exit_code, 0);
  dynamic["penalty"] = 1;
  dynamic["output"] = {{"report", "r.json"}};
  std::ofstream(dir / "own_report.json") << dynamic.dump();
  ASSERT_EQ(run("own_report.json").exit_code, 0);
  EXPECT_TRUE(fs::exists(out / "r.json"));
  EXPECT_FALSE(fs::exists(out / "report.json"));

  plate["penalty"] = 0.8;
  std::ofstream(dir / "plate.json") << plate.dump();
  const fs::path fresh = dir / "static_out";
  ASSERT_EQ(dgtex::test::run_cli("run " + (dir / "plate.json").string() + " --out " + fresh.string() + " --quiet", dir)
                .exit_code,
            0);
  EXPECT_FALSE(fs::exists(fresh / "frames"));
  nlohmann::json report;
  std::ifstream(fresh / "report.json") >> report;
  EXPECT_EQ(report["timings_ms"]["render"]["calls"], 0);
}

// An OBJ whose two quads repeat the vertices of their shared side runs as two pieces: the
// run says so (mesh_validation.h, unwelded_seam_caution) and runs.
TEST(CliRun, AnUnweldedSeamIsCautioned) {
  const fs::path dir = fresh_dir("unwelded_seam");
  std::ofstream(dir / "m.obj") << "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"
                                  "v 1 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nf 5 6 7 8\n";
  std::ofstream(dir / "seam.json") << R"({
    "mesh": {"file": "m.obj"},
    "material": {"youngs_modulus": 1e6, "poisson_ratio": 0.3, "thickness": 0.01},
    "penalty": 1,
    "boundary": [{"select": {"plane": {"normal": [1, 0, 0], "offset": 0}}, "fix": ["x", "y", "z"], "clamp": true},
                 {"select": {"plane": {"normal": [1, 0, 0], "offset": 2}}, "fix": ["x", "y", "z"], "clamp": true}],
    "loads": [{"type": "area_force", "force_per_area": [0, 0, -1]}],
    "analysis": {"type": "static"}})";
  const std::string scene = (dir / "seam.json").string();
  const Result r = dgtex::test::run_cli("run " + scene + " --out " + (dir / "out").string() + " --quiet --no-render", dir);
  EXPECT_EQ(r.exit_code, 0) << r.stderr_text;
  EXPECT_NE(r.stderr_text.find("dgtex run: warning: " + scene + ": mesh: 3 boundary nodes lie on other boundary nodes "
                               "without being joined to them"),
            std::string::npos)
      << r.stderr_text;
}

// fracture.json at T = 4096: at least 346.3 GiB of texel fields (dgtex/texel_memory_estimate.h).
// Without the check the system killed such a run minutes in; now one line, at once.
TEST(CliRun, CutsWhoseTexelFieldsCannotFitAreRefusedNamingTheResolution) {
  if (dgtex::available_memory_bytes() > std::int64_t{350} * 1000 * 1000 * 1000)
    GTEST_SKIP() << "this machine may have the memory for T = 4096";
  nlohmann::json fracture;
  std::ifstream(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/fracture.json") >> fracture;
  fracture["enrichment"]["texture_resolution"] = 4096;
  expect_rejected("texel_memory", fracture.dump(),
                  "enrichment.texture_resolution: the texel fields of 5 cut segments");
}

// A progressive cut whose new function is one too many on an element is met in a step:
// exit code 2 and the step, like any scene problem (it was exit code 1 without the step).
TEST(CliRun, AProgressiveCutsFunctionTooManyOnAnElementNamesTheStep) {
  nlohmann::json scene = nlohmann::json::parse(R"({
    "mesh": {"generator": "rectangle", "size": [0.4, 0.1], "divisions": [4, 1], "element": "quad8"},
    "material": {"youngs_modulus": 5e8, "poisson_ratio": 0.3, "thickness": 0.01, "density": 1000},
    "boundary": [{"select": {"plane": {"normal": [1, 0, 0], "offset": 0}}, "fix": ["x", "y", "z"], "clamp": true}],
    "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81]}],
    "analysis": {"type": "dynamic", "time_step": 0.005, "steps": 40},
    "enrichment": {"texture_resolution": 128}})");
  for (int k = 0; k < 32; ++k) {  // side by side in element 2, one starting each step
    const double x = 0.2 + 0.1 * (k + 0.5) / 32;
    scene["cuts"].push_back({{"points", {{x, 0, 0}, {x, 0.05, 0}}}, {"start_time", 0.005 * k}});
  }
  expect_rejected("too_many_functions", scene.dump(),
                  "step 31 (to t = 0.155): enrichment: element 1 carries 32 enrichment functions; at most 31");
}

// A material texture on an element next to a cut (not one the cut runs through): the
// element carries the cut's enrichment, and the message says so (it read "cuts through
// material-textured elements are not supported" until session 72).
TEST(CliRun, AMaterialTextureNextToACutIsRefusedNamingTheEnrichment) {
  const std::string image = std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/thickness_texture.png";
  expect_rejected("texture_next_to_cut", R"({"mesh": {"generator": "rectangle", "size": [1, 1], "divisions": [2, 2]},
      "material": {"youngs_modulus": 1e6, "poisson_ratio": 0.3, "thickness": 0.01}, "penalty": 1,
      "boundary": [{"select": {"plane": {"normal": [1, 0, 0], "offset": 0}}, "fix": ["x", "y", "z"], "clamp": true}],
      "loads": [{"type": "area_force", "force_per_area": [0, 0, -0.001]}],
      "material_textures": [{"field": "thickness", "image": ")" + image + R"(", "range": [0.005, 0.01], "elements": [0]}],
      "cuts": [{"points": [[0.6, 0.1, 0], [0.9, 0.4, 0]]}]})",
                  "element 0 has a material texture and a cut's or crease's enrichment (the elements a cut or crease "
                  "touches and their neighbours carry it)");
}

// A scene whose supports hold every node ran and wrote zeros without a word until session 72.
TEST(CliRun, ASceneThatHoldsEveryDisplacementIsCautioned) {
  const fs::path dir = fresh_dir("all_held");
  std::ofstream(dir / "scene.json") << scene("0.3", "1", R"("boundary": [{"select": {"box": {"min": [-1, -1, -1], "max": [2, 2, 1]}}, "fix": ["x", "y", "z"]}],)");
  const Result r = dgtex::test::run_cli("run " + (dir / "scene.json").string() + " --out " + (dir / "out").string() +
                                            " --quiet --no-render",
                                        dir);
  EXPECT_EQ(r.exit_code, 0) << r.stderr_text;
  EXPECT_NE(r.stderr_text.find("boundary: every displacement is held (x, y and z of all "), std::string::npos)
      << r.stderr_text;
}

TEST(CliRun, AnOutputFolderThatCannotBeCreatedIsRefusedBeforeTheScene) {
  const fs::path dir = fresh_dir("out_under_file");
  std::ofstream(dir / "file") << "not a folder";
  // The scene is not read first: the accordion's set-up would take seconds.
  const fs::path out = dir / "file" / "out";
  const Result r =
      run_dgtex(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/accordion.json --out " + out.string(), dir);
  EXPECT_EQ(r.exit_code, 2) << r.stderr_text;
  EXPECT_NE(r.stderr_text.find("--out: '" + (dir / "file").string() + "' is not a folder"), std::string::npos)
      << r.stderr_text;
  EXPECT_FALSE(fs::exists(out));
}

// The demo cantilever without frames to draw, for STEPS steps, writing a VTU frame every 10.
fs::path cantilever_scene(const fs::path& dir, int steps) {
  nlohmann::json scene;
  std::ifstream(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/demo_cantilever.json") >> scene;
  scene["analysis"]["steps"] = steps;
  scene.erase("render");
  const fs::path path = dir / ("cantilever_" + std::to_string(steps) + ".json");
  std::ofstream(path) << scene.dump();
  return path;
}

// Starts `dgtex run SCENE --out OUT --quiet` (stderr into DIR/stderr.txt), waits until FILE
// exists, sends SIGNALS one right after the other and returns the wait status (-1 if the
// run did not end within a minute).
int run_and_interrupt(const fs::path& scene, const fs::path& out, const fs::path& file,
                      std::initializer_list<int> signals, const fs::path& dir) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    const std::string err = (dir / "stderr.txt").string();
    if (!std::freopen(err.c_str(), "w", stderr)) ::_exit(127);
    ::execl(DGTEX_CLI, DGTEX_CLI, "run", scene.c_str(), "--out", out.c_str(), "--quiet", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(1);
  while (!fs::exists(file) && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  for (const int signal_number : signals) ::kill(pid, signal_number);
  int status = 0;
  while (::waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(pid, SIGKILL);
      ::waitpid(pid, &status, 0);
      return -1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return status;
}

// A long run stopped by Ctrl-C or a batch system's time limit keeps what it has: the
// frame and mesh of the step it reached and a report saying so, with exit code 128 + signal.
TEST(CliRun, AnInterruptedRunWritesTheStepItReachedAndSaysSo) {
  const fs::path dir = fresh_dir("interrupted");
  const fs::path scene = cantilever_scene(dir, 1000000);  // hours of steps
  for (const int signal_number : {SIGINT, SIGTERM}) {
    const fs::path out = dir / ("out_" + std::to_string(signal_number));
    const int status = run_and_interrupt(scene, out, out / "frames" / "frame_00020.vtu", {signal_number}, dir);
    std::ifstream err(dir / "stderr.txt");
    const std::string stderr_text((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
    ASSERT_TRUE(status != -1 && WIFEXITED(status)) << stderr_text;
    ASSERT_EQ(WEXITSTATUS(status), 128 + signal_number) << stderr_text;
    const std::string name = signal_number == SIGINT ? "SIGINT" : "SIGTERM";
    EXPECT_NE(stderr_text.find("interrupted by " + name + " at step "), std::string::npos) << stderr_text;
    std::ifstream in(out / "report.json");
    const nlohmann::json report = nlohmann::json::parse(in);
    EXPECT_EQ(report["completed"], false);
    EXPECT_EQ(report["interrupted_by"], name);
    const int steps = report["steps_completed"];
    EXPECT_GE(steps, 20);
    EXPECT_LT(steps, 1000000);
    EXPECT_NEAR(report["time"].get<double>(), steps * 0.005, 1e-9);
    EXPECT_EQ(report["timings_ms"]["assembly"]["calls"], steps);
    char frame[32];
    std::snprintf(frame, sizeof frame, "frame_%05d.vtu", steps);
    EXPECT_TRUE(fs::exists(out / "frames" / frame)) << frame;
    EXPECT_TRUE(fs::exists(out / "deformed.vtu"));
  }
}

// A second signal ends the run at once, also when it is the other of the two: after Ctrl-C,
// a batch system's SIGTERM was only noted until session 72 (the handlers fell back to the
// default one signal at a time). Sent together, either may be handled first (the kernel
// delivers the lower number first, or each to a thread of its own): the process ends by one.
TEST(CliRun, ASecondSignalOfEitherKindEndsTheRunAtOnce) {
  const fs::path dir = fresh_dir("interrupted_twice");
  const fs::path scene = cantilever_scene(dir, 1000000);
  for (const auto& [first, second] : {std::pair{SIGINT, SIGTERM}, std::pair{SIGTERM, SIGINT}}) {
    const fs::path out = dir / ("out_" + std::to_string(first));
    const int status = run_and_interrupt(scene, out, out / "frames" / "frame_00020.vtu", {first, second}, dir);
    ASSERT_NE(status, -1);
    EXPECT_TRUE(WIFSIGNALED(status) && (WTERMSIG(status) == SIGINT || WTERMSIG(status) == SIGTERM))
        << "signals " << first << " and " << second << ": exit code " << WEXITSTATUS(status);
    EXPECT_FALSE(fs::exists(out / "report.json"));
  }
}

// A run into a folder an earlier run wrote: none of the earlier run's frames or report stay
// beside the new run's (a shorter run's folder showed the longer run's last frames).
TEST(CliRun, ARunRemovesTheOutputsOfAnEarlierRunIntoItsFolder) {
  const fs::path dir = fresh_dir("earlier_outputs");
  const fs::path out = dir / "out";
  ASSERT_EQ(run_dgtex(cantilever_scene(dir, 30).string() + " --out " + out.string(), dir).exit_code, 0);
  ASSERT_TRUE(fs::exists(out / "frames" / "frame_00030.vtu"));
  std::ofstream(out / "frames" / "frame_00040.png") << "a frame";
  std::ofstream(out / "frames" / "notes.txt") << "not dgtex's";
  std::ofstream(out / "final.state") << "an earlier state";
  const Result r = dgtex::test::run_cli("run " + cantilever_scene(dir, 10).string() + " --out " + out.string(), dir);
  ASSERT_EQ(r.exit_code, 0) << r.stderr_text;
  EXPECT_NE(r.stderr_text.find("removed 8 files of an earlier run from " + out.string()), std::string::npos)
      << r.stderr_text;  // frames 0, 10, 20, 30 and 40, the report, deformed.vtu, final.state
  EXPECT_TRUE(fs::exists(out / "frames" / "frame_00010.vtu"));
  EXPECT_FALSE(fs::exists(out / "frames" / "frame_00020.vtu"));
  EXPECT_FALSE(fs::exists(out / "frames" / "frame_00030.vtu"));
  EXPECT_FALSE(fs::exists(out / "frames" / "frame_00040.png"));
  EXPECT_FALSE(fs::exists(out / "final.state"));
  EXPECT_TRUE(fs::exists(out / "frames" / "notes.txt"));
  std::ifstream in(out / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["completed"], true);
  EXPECT_EQ(report["steps_completed"], 10);
}

}  // namespace
