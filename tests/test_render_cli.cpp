// `dgtex render STATE --out DIR|FILE.png`: success, bad input (exit 2) and no EGL (exit 1 with
// the documented one-line message).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "dgtex/png_io.h"
#include "dgtex/shell_state.h"
#include "render_fixtures.h"

namespace dgtex {
namespace {

namespace fs = std::filesystem;

fs::path work_dir() {
  const fs::path dir = fs::path(::testing::TempDir()) / "dgtex_render_cli";
  fs::create_directories(dir);
  return dir;
}

struct CliResult {
  int exit_code;
  std::string out, err;
};

// Runs the dgtex executable through the shell with an environment prefix.
CliResult run_cli(const std::string& environment, const std::string& arguments) {
  // Per-test files: CTest runs the test cases of this executable in parallel.
  const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  const fs::path out = work_dir() / (test + ".stdout.txt"), err = work_dir() / (test + ".stderr.txt");
  const std::string command = environment + " '" + std::string(DGTEX_CLI) + "' render " + arguments + " >'" +
                              out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(command.c_str());
  auto slurp = [](const fs::path& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  };
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

std::string saved_plate() {
  const std::string test = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  const std::string path = (work_dir() / (test + ".plate.state")).string();
  save_state(path, test::straight_cut_plate().state);
  return path;
}

TEST(RenderCli, RendersAStateToFramePng) {
  const fs::path out = work_dir() / "ok";
  fs::remove_all(out);
  const CliResult r = run_cli("", "'" + saved_plate() + "' --out '" + out.string() +
                                "' --width 96 --height 64 --shading smooth --wireframe --cut-method drop-triangles");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image image = read_png((out / "frame.png").string());
  EXPECT_EQ(image.width, 96);
  EXPECT_EQ(image.height, 64);
  EXPECT_NE(r.out.find("frame.png"), std::string::npos);
}

// A view close enough that the viewport clips triangles (the demo cantilever's final state,
// from above): the wireframe stays lines. Edge distances computed in the geometry stage from
// the projected corners, interpolated noperspective, painted the clipped corner triangles
// solid red (25k of 360k pixels).
TEST(RenderCli, AClippedWireframeStaysLines) {
  const fs::path dir = work_dir() / "clipped_wireframe";
  fs::remove_all(dir);
  const std::string run = "'" + std::string(DGTEX_CLI) + "' run '" + std::string(DGTEX_SOURCE_DIR) +
                          "/examples/scenes/demo_cantilever.json' --out '" + dir.string() +
                          "' --save-state --no-render --quiet";
  ASSERT_EQ(std::system(run.c_str()), 0);
  const std::string png = (dir / "zoom.png").string();
  const CliResult r = run_cli("", "'" + (dir / "final.state").string() + "' --out '" + png +
                                      "' --width 600 --height 600 --camera-position 0.5 0.1 0.12 --camera-target 0.5 "
                                      "0.1 -0.05 --camera-up 0 1 0 --fov 30 --wireframe");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image image = read_png(png);
  auto red = [&](int x, int y) {
    const std::uint8_t* p = image.pixel(x, y);
    return p[0] > 180 && p[1] < 40 && p[2] < 40;
  };
  int red_pixels = 0, red_blocks = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) red_pixels += red(x, y);
  // Lines are 1-2 pixels wide (2-3 where they cross): no 5 x 5 block is all red.
  for (int y = 0; y + 5 <= image.height; ++y)
    for (int x = 0; x + 5 <= image.width; ++x) {
      bool all = true;
      for (int j = 0; j < 5 && all; ++j)
        for (int i = 0; i < 5 && all; ++i) all = red(x + i, y + j);
      red_blocks += all;
    }
  EXPECT_GT(red_pixels, 2000);  // the lines are there
  EXPECT_EQ(red_blocks, 0) << red_pixels << " red pixels";
}

// `--out NAME.png` is the image itself (it was a folder NAME.png holding frame.png); an
// existing folder of that name still gets its frame.png.
TEST(RenderCli, AnOutEndingInPngNamesTheImage) {
  const fs::path dir = work_dir() / "png_out";
  fs::remove_all(dir);
  const fs::path image = dir / "new" / "spiral.PNG";
  CliResult r = run_cli("", "'" + saved_plate() + "' --out '" + image.string() + "' --width 40 --height 30");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_TRUE(fs::is_regular_file(image));
  EXPECT_EQ(read_png(image.string()).width, 40);
  EXPECT_NE(r.out.find("wrote " + image.string() + " (40 x 30;"), std::string::npos) << r.out;
  const fs::path folder = dir / "folder.png";
  fs::create_directories(folder);
  r = run_cli("", "'" + saved_plate() + "' --out '" + folder.string() + "' --width 40 --height 30");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::is_regular_file(folder / "frame.png"));
  r = run_cli("", "'" + saved_plate() + "' --out '" + (dir / "new" / "spiral.PNG" / "x.png").string() + "'");
  EXPECT_EQ(r.exit_code, 2);  // under a file
  EXPECT_NE(r.err.find("'" + image.string() + "' is not a folder"), std::string::npos) << r.err;
}

TEST(RenderCli, BadInputExitsWithTwo) {
  const std::string out = (work_dir() / "bad").string();
  CliResult r = run_cli("", "'" + (work_dir() / "missing.state").string() + "' --out '" + out + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("missing.state"), std::string::npos) << r.err;
  r = run_cli("", "'" + saved_plate() + "' --out '" + out + "' --shading glossy");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("valid: flat, smooth"), std::string::npos) << r.err;
  r = run_cli("", "'" + saved_plate() + "' --out '" + out + "' --cut-method scissors");
  EXPECT_EQ(r.exit_code, 2);
  r = run_cli("", "'" + saved_plate() + "'");  // no --out
  EXPECT_EQ(r.exit_code, 2);
  r = run_cli("", "'" + saved_plate() + "' --out '" + out + "' --width 0");
  EXPECT_EQ(r.exit_code, 2);
  const std::string state = saved_plate();
  r = run_cli("", "'" + state + "' --out '" + state + "/out'");  // the state file is no folder
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--out: '" + state + "' is not a folder"), std::string::npos) << r.err;
  // A state without elements: the library draws the background, the command refuses it
  // (it wrote a blank image and reported success).
  const std::string empty = (work_dir() / "empty.state").string();
  save_state(empty, ShellState{});
  r = run_cli("", "'" + empty + "' --out '" + out + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("state file '" + empty + "': no elements to draw"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(fs::path(out) / "frame.png"));
}

// With glvnd pointed at a vendor file that does not exist no EGL implementation loads:
// the command must fail with exit code 1 and one line saying what was tried.
TEST(RenderCli, NoEglFailsWithOneLineAndExitCodeOne) {
  const std::string out = (work_dir() / "noegl").string();
  const CliResult r = run_cli("env -u EGL_PLATFORM __EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent.json",
                        "'" + saved_plate() + "' --out '" + out + "'");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  const std::string prefix = "dgtex render: no OpenGL 3.3+ core context through EGL (tried: ";
  EXPECT_EQ(r.err.rfind(prefix, 0), 0u) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(fs::path(out) / "frame.png"));
}

TEST(RenderCli, SurfacelessPlatformFallbackRenders) {
  const fs::path out = work_dir() / "surfaceless";
  const CliResult r = run_cli("env DGTEX_EGL_DEVICE=surfaceless", "'" + saved_plate() + "' --out '" + out.string() +
                                                                      "' --width 32 --height 24");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("EGL_MESA_platform_surfaceless"), std::string::npos) << r.out;
  EXPECT_EQ(read_png((out / "frame.png").string()).width, 32);
}

TEST(RenderCli, BadDeviceIndexIsReported) {
  const std::string out = (work_dir() / "baddevice").string();
  const CliResult r = run_cli("env DGTEX_EGL_DEVICE=99", "'" + saved_plate() + "' --out '" + out + "'");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("DGTEX_EGL_DEVICE=99"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace dgtex
