// `dgtex run` with a render block: PNG frames (runtime/frame_writer.cpp) from the
// executable, the camera of a scene without one, --no-render, --obj, and the failure
// without EGL (exit code 1, one line, nothing written).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "dgtex/frame_writer.h"
#include "dgtex/png_io.h"
#include "dgtex/shell_state.h"
#include "render_fixtures.h"

namespace dgtex {
namespace {

namespace fs = std::filesystem;

// A fresh folder per test case (CTest runs the cases of this executable in parallel).
fs::path test_dir() {
  const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  const fs::path dir = fs::path(::testing::TempDir()) / ("dgtex_render_run_" + test);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

struct CliResult {
  int exit_code;
  std::string err;
};

CliResult run_dgtex(const std::string& environment, const std::string& arguments, const fs::path& dir) {
  const fs::path err = dir / "stderr.txt";
  const std::string command = environment + " '" + std::string(DGTEX_CLI) + "' run " + arguments + " --quiet >/dev/null 2>'" +
                              err.string() + "'";
  const int status = std::system(command.c_str());
  std::ifstream in(err);
  std::stringstream text;
  text << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, text.str()};
}

// A 2 x 1 clamped strip under gravity; ANALYSIS and RENDER are substituted.
std::string strip_scene(const std::string& analysis, const std::string& render) {
  std::string s = R"({"mesh": {"generator": "rectangle", "size": [1.0, 0.25], "divisions": [4, 1], "element": "quad8"},
  "material": {"youngs_modulus": 1e8, "poisson_ratio": 0.3, "thickness": 0.01, "density": 100},
  "penalty": 1,
  "boundary": [{"select": {"plane": {"normal": [1, 0, 0], "offset": 0}}, "fix": ["x", "y", "z"], "clamp": true}],
  "loads": [{"type": "gravity", "acceleration": [0, 0, -9.81]}],
  "analysis": ANALYSIS RENDER})";
  s.replace(s.find("ANALYSIS"), 8, analysis);
  s.replace(s.find("RENDER"), 6, render);
  return s;
}

const char* kDynamic = R"({"type": "dynamic", "time_step": 0.03, "steps": 7, "damping": {"mass": 1.0}})";
const char* kStatic = R"({"type": "static"})";
const char* kRenderBlock = R"(, "render": {"width": 96, "height": 64, "every_steps": 3, "background": [0.2, 0.4, 0.6],
  "camera": {"position": [0.5, -1.5, 1.0], "target": [0.5, 0.1, -0.1]}})";

std::vector<std::string> png_files(const fs::path& frames) {
  std::vector<std::string> names;
  if (fs::exists(frames))
    for (const auto& entry : fs::directory_iterator(frames))
      if (entry.path().extension() == ".png") names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

long covered_pixels(const Image& image, const float background[3]) {
  long covered = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) covered += !test::is_background(image, x, y, background);
  return covered;
}

TEST(RenderRunFrames, DynamicSceneWritesEveryNthStepAndTheFinalState) {
  const fs::path dir = test_dir();
  std::ofstream(dir / "scene.json") << strip_scene(kDynamic, kRenderBlock);
  const CliResult r = run_dgtex("", "'" + (dir / "scene.json").string() + "' --out '" + (dir / "out").string() + "'", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // Steps 0, 3, 6 and the final step 7.
  const std::vector<std::string> expected = {"frame_00000.png", "frame_00003.png", "frame_00006.png", "frame_00007.png"};
  EXPECT_EQ(png_files(dir / "out" / "frames"), expected);
  const float background[3] = {0.2f, 0.4f, 0.6f};
  std::vector<Image> images;
  for (const std::string& name : expected) {
    const Image image = read_png((dir / "out" / "frames" / name).string());
    EXPECT_EQ(image.width, 96);
    EXPECT_EQ(image.height, 64);
    const long covered = covered_pixels(image, background);
    EXPECT_GT(covered, 96 * 64 / 50) << name;  // the strip is in view
    EXPECT_LT(covered, 96 * 64) << name;       // and the background too
    images.push_back(image);
  }
  long changed = 0;  // the strip has moved between the first and the last frame
  for (size_t i = 0; i < images.front().rgba.size(); i += 4) changed += images.front().rgba[i] != images.back().rgba[i];
  EXPECT_GT(changed, 10);
  std::ifstream in(dir / "out" / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["timings_ms"]["render"]["calls"], 4);
  EXPECT_GT(report["timings_ms"]["render"]["mean"].get<double>(), 0.0);
}

TEST(RenderRunFrames, StaticSceneWritesOneFrameOfTheFinalState) {
  const fs::path dir = test_dir();
  std::ofstream(dir / "scene.json") << strip_scene(kStatic, kRenderBlock);
  const CliResult r = run_dgtex("", "'" + (dir / "scene.json").string() + "' --out '" + (dir / "out").string() + "' --obj", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(png_files(dir / "out" / "frames"), std::vector<std::string>{"frame_00000.png"});
  const Image image = read_png((dir / "out" / "frames" / "frame_00000.png").string());
  const float background[3] = {0.2f, 0.4f, 0.6f};
  EXPECT_GT(covered_pixels(image, background), 96 * 64 / 50);
  // --obj: the final surface, 4 elements of 8 x 8 quads each.
  std::ifstream obj(dir / "out" / "cut_surface.obj");
  std::string line;
  int faces = 0, vertices = 0;
  while (std::getline(obj, line)) {
    faces += line.rfind("f ", 0) == 0;
    vertices += line.rfind("v ", 0) == 0;
  }
  EXPECT_EQ(faces, 4 * 8 * 8);
  EXPECT_EQ(vertices, (4 * 8 + 1) * (8 + 1));  // welded across element edges
}

TEST(RenderRunFrames, NoRenderBlockOrNoRenderFlagWritesNoPng) {
  const fs::path dir = test_dir();
  std::ofstream(dir / "with.json") << strip_scene(kStatic, kRenderBlock);
  std::ofstream(dir / "without.json") << strip_scene(kStatic, "");
  CliResult r = run_dgtex("", "'" + (dir / "with.json").string() + "' --out '" + (dir / "a").string() + "' --no-render", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(png_files(dir / "a" / "frames").empty());
  EXPECT_TRUE(fs::exists(dir / "a" / "report.json"));
  r = run_dgtex("", "'" + (dir / "without.json").string() + "' --out '" + (dir / "b").string() + "'", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(png_files(dir / "b" / "frames").empty());
  std::ifstream in(dir / "b" / "report.json");
  // Every stage is in the report, one that did not run with 0 calls (README "Running a scene").
  EXPECT_EQ(nlohmann::json::parse(in)["timings_ms"]["render"]["calls"], 0);
}

// --save-state writes the final state; `dgtex render` of it with the scene's camera, size
// and background draws bitwise the run's last frame (same renderer, state saved exactly:
// f64 positions and displacements, the f32 textures as they are held).
TEST(RenderRunFrames, SavedFinalStateRendersToTheLastFrame) {
  const fs::path dir = test_dir();
  const std::string cut =
      R"(, "cuts": [{"points": [[0.6, 0, 0], [0.6, 0.15, 0]]}], "enrichment": {"texture_resolution": 32})";
  std::ofstream(dir / "scene.json") << strip_scene(kDynamic, kRenderBlock + cut);
  const fs::path out = dir / "out";
  const CliResult r =
      run_dgtex("", "'" + (dir / "scene.json").string() + "' --out '" + out.string() + "' --save-state", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ShellState uncut = load_state((out / "final.state").string());
  ASSERT_FALSE(uncut.enrichments.empty());  // the cut's textures travel
  uncut.enrichments.clear();
  save_state((dir / "uncut.state").string(), uncut);
  const auto render = [&](const fs::path& state, const fs::path& folder) {
    const std::string command = "'" + std::string(DGTEX_CLI) + "' render '" + state.string() + "' --out '" +
                                folder.string() +
                                "' --width 96 --height 64 --background 0.2 0.4 0.6 --camera-position 0.5 -1.5 1.0"
                                " --camera-target 0.5 0.1 -0.1 >/dev/null 2>&1";
    EXPECT_EQ(std::system(command.c_str()), 0) << command;
    return read_png((folder / "frame.png").string());
  };
  const Image last = read_png((out / "frames" / "frame_00007.png").string());
  const Image rendered = render(out / "final.state", dir / "again");
  EXPECT_EQ(rendered.width, last.width);
  EXPECT_EQ(rendered.height, last.height);
  EXPECT_TRUE(rendered.rgba == last.rgba) << "the rendered state differs from the run's final frame";
  // The comparison sees the cut: without its enrichments the same state draws differently.
  EXPECT_FALSE(render(dir / "uncut.state", dir / "uncut").rgba == last.rgba);
}

// glvnd pointed at a vendor file that does not exist loads no EGL implementation.
const char* kNoEgl = "env -u EGL_PLATFORM __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json";

TEST(RenderRunFrames, WithoutEglARenderBlockFailsBeforeWritingAnything) {
  const fs::path dir = test_dir();
  std::ofstream(dir / "scene.json") << strip_scene(kDynamic, kRenderBlock);
  const fs::path out = dir / "out";
  const CliResult r = run_dgtex(kNoEgl, "'" + (dir / "scene.json").string() + "' --out '" + out.string() + "'", dir);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  const std::string prefix = "dgtex run: no OpenGL 3.3+ core context through EGL (tried: ";
  EXPECT_EQ(r.err.rfind(prefix, 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(out)) << "the output folder was created";
  // Without frames the same machine runs the scene.
  const CliResult plain =
      run_dgtex(kNoEgl, "'" + (dir / "scene.json").string() + "' --out '" + out.string() + "' --no-render", dir);
  EXPECT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_TRUE(fs::exists(out / "report.json"));
  EXPECT_TRUE(png_files(out / "frames").empty());
}

// A render block without a camera frames the shell: it is in view, away from the borders.
TEST(RenderRunFrames, DefaultCameraFramesTheShell) {
  const fs::path dir = test_dir();
  std::ofstream(dir / "scene.json") << strip_scene(kStatic, R"(, "render": {"width": 120, "height": 90})");
  const CliResult r = run_dgtex("", "'" + (dir / "scene.json").string() + "' --out '" + (dir / "out").string() + "'", dir);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image image = read_png((dir / "out" / "frames" / "frame_00000.png").string());
  const float white[3] = {1, 1, 1};
  int lo_x = image.width, hi_x = -1, lo_y = image.height, hi_y = -1;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      if (!test::is_background(image, x, y, white)) {
        lo_x = std::min(lo_x, x), hi_x = std::max(hi_x, x);
        lo_y = std::min(lo_y, y), hi_y = std::max(hi_y, y);
      }
  ASSERT_GE(hi_x, 0) << "nothing drawn";
  EXPECT_GT(lo_x, 0);
  EXPECT_LT(hi_x, image.width - 1);
  EXPECT_GT(lo_y, 0);
  EXPECT_LT(hi_y, image.height - 1);
  EXPECT_GT(hi_x - lo_x, image.width / 2);  // and fills a good part of it
}

// resolve_scene_camera: given values are kept; missing ones frame the state's bounds.
TEST(RenderRunFrames, SceneCameraResolution) {
  ShellState state;
  state.mesh = test::rectangle_mesh(ElementType::quad8, 2, 1, 2.0, 1.0);  // box centre (1, 0.5, 0)
  RenderOptions options;
  RenderSettings s = scene_render_settings(options, state);
  EXPECT_EQ(s.width, 640);
  EXPECT_FALSE(s.auto_camera);
  EXPECT_DOUBLE_EQ(s.camera_target[0], 1.0);
  EXPECT_DOUBLE_EQ(s.camera_target[1], 0.5);
  EXPECT_DOUBLE_EQ(s.camera_target[2], 0.0);
  // Along the default direction, far enough that the bounding sphere (radius sqrt(1.25)) fits.
  double offset[3], length = 0, along = 0, direction = 0;
  for (int d = 0; d < 3; ++d) {
    offset[d] = s.camera_position[d] - s.camera_target[d];
    length += offset[d] * offset[d];
    direction += kDefaultViewDirection[d] * kDefaultViewDirection[d];
  }
  for (int d = 0; d < 3; ++d) along += offset[d] * kDefaultViewDirection[d];
  EXPECT_NEAR(along / std::sqrt(length * direction), 1.0, 1e-12);
  EXPECT_NEAR(std::sqrt(length), 1.1 * std::sqrt(1.25) / std::sin(20.0 * M_PI / 180.0), 1e-9);

  options.camera_position = Vec3{3, -4, 5};
  s = scene_render_settings(options, state);
  EXPECT_DOUBLE_EQ(s.camera_position[0], 3);
  EXPECT_DOUBLE_EQ(s.camera_target[0], 1.0);  // box centre
  options.camera_target = Vec3{0, 0, 0};
  options.shading = RenderOptions::Shading::smooth;
  options.background = {0, 0, 1};
  s = scene_render_settings(options, state);
  EXPECT_DOUBLE_EQ(s.camera_target[1], 0.0);
  EXPECT_EQ(s.shading, RenderSettings::Shading::smooth);
  EXPECT_FLOAT_EQ(s.background[2], 1.0f);
  EXPECT_EQ(png_frame_name(42), "frame_00042.png");
}

}  // namespace
}  // namespace dgtex
