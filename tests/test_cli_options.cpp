// Command-line values of every command, as a fuzzing pass over the options found them
// (session 67): each bad value ends the command at once with exit code 2 and one line naming
// the command, the option and the value; a write that fails says so (exit code 1).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "cli_test_support.h"

namespace fs = std::filesystem;

namespace {

using dgtex::test::CliResult;
using dgtex::test::run_cli;

const std::string kScenes = std::string(DGTEX_SOURCE_DIR) + "/examples/scenes";

struct Refusal {
  const char* args;
  const char* message_start;  // the whole of stderr starts with it
};

TEST(CliOptions, BadValuesAreOneLineNamingTheCommandAndOption) {
  const fs::path dir = dgtex::test::fresh_dir("dgtex_cli_options", "refusals");
  const std::string plate = kScenes + "/clamped_plate.json";
  const Refusal refusals[] = {
      // CLI11's own errors, which it followed with "Run with --help for more information."
      {"run PLATE --out DIR/o --bogus", "dgtex run: The following argument was not expected: --bogus (see dgtex run --help)"},
      {"bench scenes --threads 0", "dgtex bench scenes: --threads: Value 0 not in range 1 to 1024"},
      // An empty path is a given option, not a missing one: --out '' wrote into the
      // working folder and removed an earlier run's files there.
      {"run PLATE --out ''", "dgtex run: --out: an empty path; give a folder"},
      {"bench scaling --json ''", "dgtex bench scaling: --json: an empty path; give a file name"},
      {"bench accuracy --out ''", "dgtex bench accuracy: --out: an empty path"},
      {"render x.state --out ''", "dgtex render: --out: an empty path"},
      // Names over 255 bytes failed only when written, after the work.
      {"bench scaling --json DIR/NAME300.json", "dgtex bench scaling: --json: a name in '"},
      {"run PLATE --out DIR/NAME300", "dgtex run: --out: a name in '"},
      // So did paths over the system's 4096 bytes made of short names (session 71).
      {"run PLATE --out DIR/LONGPATH", "dgtex run: --out: the path has "},
      {"bench scaling --json DIR/LONGPATH.json", "dgtex bench scaling: --json: the path has "},
      // The permission bits, which root passes, took /proc: the run failed after its work.
      {"run PLATE --out /proc/dgtex_out", "dgtex run: --out: folder '/proc' is not writable"},
      {"bench scenes --json /proc/dgtex.json", "dgtex bench scenes: --json: folder '/proc' is not writable"},
      // Tolerances no solve can meet, or that any guess meets.
      {"bench shell --tolerance 0", "dgtex bench shell: --tolerance: Value 0 is not a relative tolerance"},
      {"bench shell --tolerance -1", "dgtex bench shell: --tolerance: Value -1 is not a relative tolerance"},
      {"bench laplace --tolerance 1", "dgtex bench laplace: --tolerance: Value 1 is not a relative tolerance"},
      {"render x.state --background 2 0 0", "dgtex render: --background: Value 2 not in range"},
      // Passed CLI11's range (NaN), or were refused by the library naming its own fields.
      {"render x.state --out DIR/r.png --background nan 0 0", "dgtex render: --background: nan 0 0: expected three numbers in [0, 1]"},
      {"render x.state --out DIR/r.png --camera-up 0 0 0", "dgtex render: --camera-up: 0 0 0: expected a non-zero direction"},
      {"render x.state --out DIR/r.png --fov 180", "dgtex render: --fov: 180: expected more than 0 and less than 180 degrees"},
      {"render x.state --out DIR/r.png --camera-position 1 1 1 --camera-target 1 1 1",
       "dgtex render: --camera-target: 1 1 1: the camera's own position"},
      {"render x.state --out DIR/r.png --shading bogus", "dgtex render: --shading: shading 'bogus' (valid: flat, smooth)"},
      {"render x.state --out DIR/r.png --camera-position 0 0 5 --camera-up 0 0 1",
       "dgtex render: --camera-up: 0 0 1: parallel to the viewing direction"},
      {"bench scenes --threads 1 --cut-update-threads 1",
       "dgtex bench scenes: --cut-update-threads: 1 is more than the steps' threads (1) can spare"},
      {"bench scaling --threads-list 2,1", "dgtex bench scaling: --threads-list: 2,1; expected increasing thread counts"},
      {"bench accuracy --shell-scene DIR/missing.json", "dgtex bench accuracy: --shell-scene: File does not exist: "},
      // A chart case not among the cases run was found missing only at the end.
      {"bench laplace --sizes 16 --domains open --chart DIR/c.svg",
       "dgtex bench laplace: --chart-domain: slit is not among --domains"},
      {"bench laplace --sizes 16 --domains open --chart DIR/c.svg --chart-domain open",
       "dgtex bench laplace: --chart-size: 512 is not among --sizes"},
      {"bench laplace --max-other-unknowns -1", "dgtex bench laplace: --max-other-unknowns: Value -1 not in range"},
      {"bench shell --refactor-after -1", "dgtex bench shell: --refactor-after: Value -1 not in range"},
      // A bad value of a later sweep ended the command after the earlier sweeps' minutes.
      {"bench accuracy --charts texture,plate --texture-sizes 16 --plate-divisions 3 --out DIR/acc",
       "dgtex bench accuracy: --plate-divisions: plate divisions: n = 3; need an even n"},
      {"bench accuracy --charts platee --out DIR/acc",
       "dgtex bench accuracy: --charts: unknown chart 'platee'; valid: plate, quadrature, texture, tolerance, rotation, "
       "scene_quadrature (see dgtex bench accuracy --help)"},
      {"bench accuracy --charts tolerance --no-shell --no-multigrid --out DIR/acc",
       "dgtex bench accuracy: tolerance accuracy: neither the shell nor the multigrid series is on"},
      // Sizes that failed only once their sweep ran (exit 1, or a bare std::bad_alloc), and a
      // reference looser than the runs measured against it.
      {"bench accuracy --charts quadrature --quadrature-resolution 100 --out DIR/acc",
       "dgtex bench accuracy: --quadrature-resolution: quadrature resolution T = 100; need a power of two in 8..4096"},
      {"bench accuracy --charts texture --texture-sizes 16,100000 --out DIR/acc",
       "dgtex bench accuracy: --texture-sizes: texture size T = 100000; need an even T in 16..4096"},
      {"bench accuracy --charts tolerance --no-shell --multigrid-size 3 --out DIR/acc",
       "dgtex bench accuracy: --multigrid-size: tolerance accuracy: multigrid size T = 3; need 16..2048"},
      {"bench accuracy --charts tolerance --multigrid-tolerances 2 --out DIR/acc",
       "dgtex bench accuracy: --multigrid-tolerances: tolerance accuracy: multigrid tolerance 2; need 1e-12 <= tol < 1"},
      {"bench accuracy --charts scene_quadrature --scene-quadrature-reference 2 --out DIR/acc",
       "dgtex bench accuracy: scene quadrature accuracy: reference tolerance 2; need one at or below every swept"},
      // Numbers CLI11 read its own way: "1e3" and "2.5" called out of range, "0x10" taken as 16.
      {"run PLATE --out DIR/o --threads 0x10", "dgtex run: --threads: Value 0x10 is not a whole number in decimal digits"},
      {"render x.state --out DIR/r.png --width 2.5", "dgtex render: --width: Value 2.5 is not a whole number"},
      {"bench laplace --sizes 16,1e3", "dgtex bench laplace: --sizes: Value 1e3 is not a whole number"},
      // Per-step times for 2^31 steps (32 GiB), with no word for hours.
      {"bench shell --steps 2000000", "dgtex bench shell: --steps: Value 2000000 not in range 1 to 1000000"},
      // CLI11 dropped empty list items and kept repeats (a case run and reported twice).
      {"bench laplace --sizes 16,,32", "dgtex bench laplace: --sizes: '16,,32' has an empty item"},
      {"bench laplace --sizes=16,32,", "dgtex bench laplace: --sizes: '16,32,' has an empty item"},
      {"bench render --tessellations 1,1", "dgtex bench render: --tessellations: '1,1' names 1 twice"},
      {"bench shell --threads-list 2,1", "dgtex bench shell: --threads-list: 2,1; expected increasing thread counts"},
      // Tolerances round-off keeps a solve from reaching: they failed after the work began.
      {"bench laplace --tolerance 1e-300",
       "dgtex bench laplace: --tolerance: Value 1e-300 is not a relative tolerance a double-precision solve can reach"},
      {"bench accuracy --charts tolerance --shell-tolerances 1e-300 --out DIR/acc",
       "dgtex bench accuracy: --shell-tolerances: tolerance accuracy: shell tolerance 1e-300; need 1e-12 <= tol < 1"},
      // Values the sweep's scene would refuse only once the sweep ran, and the options of a
      // chart not chosen (ignored without a word).
      {"bench accuracy --charts quadrature --quadrature-tolerances inf --out DIR/acc",
       "dgtex bench accuracy: --quadrature-tolerances: quadrature tolerance inf; need 1e-30 <= tol <= 1e30"},
      // 1e-300 ran, and the chart's log axis failed in gnuplot (exit code 1; session 71).
      {"bench accuracy --charts quadrature --quadrature-tolerances 1e-300 --out DIR/acc",
       "dgtex bench accuracy: --quadrature-tolerances: quadrature tolerance 1e-300; need 1e-30 <= tol <= 1e30"},
      // Finite, but its length overflowed, and the message called it not finite.
      {"render x.state --out DIR/x.png --camera-position 1e200 0 0",
       "dgtex render: --camera-position: 1e+200 0 0: expected finite numbers of magnitude up to 1e30"},
      {"bench accuracy --charts rotation --rotation-blocks 100000 --out DIR/acc",
       "dgtex bench accuracy: --rotation-blocks: rotation accuracy: rotation block B = 100000 texels; need 1..4096"},
      {"bench accuracy --charts plate --texture-sizes -5 --out DIR/acc", "dgtex bench accuracy: --texture-sizes: texture size T = -5"},
      // One file for two outputs kept only the one written last.
      {"bench scaling --json DIR/a.json --markdown DIR/a.json",
       "dgtex bench scaling: --json and --markdown both name '"},
      {"bench shell --json DIR/a.json --chart DIR/./a.json", "dgtex bench shell: --json and --chart both name '"},
  };
  for (const Refusal& refusal : refusals) {
    std::string args = refusal.args;
    auto replace = [&](const std::string& from, const std::string& to) {
      for (std::size_t at = args.find(from); at != std::string::npos; at = args.find(from, at + to.size()))
        args.replace(at, from.size(), to);
    };
    replace("NAME300", std::string(300, 'n'));
    std::string long_path = "p";
    while (long_path.size() < 4200) long_path += "/abcdefgh";
    replace("LONGPATH", long_path);
    replace("PLATE", plate);
    replace("DIR", dir.string());
    const CliResult r = run_cli(args, dir);
    EXPECT_EQ(r.exit_code, 2) << refusal.args << ": " << r.stderr_text;
    EXPECT_EQ(r.stderr_text.rfind(refusal.message_start, 0), 0u) << refusal.args << ": " << r.stderr_text;
    EXPECT_EQ(std::count(r.stderr_text.begin(), r.stderr_text.end(), '\n'), 1) << refusal.args << ": " << r.stderr_text;
  }
  EXPECT_FALSE(fs::exists(dir / "a.json"));
  EXPECT_FALSE(fs::exists(dir / "acc"));  // refused before the output folder and the first sweep
}

// Sizes a benchmark allocates at once ended it with a bare "std::bad_alloc" (exit code 1);
// with 64 MiB to use (DGTEX_MEMORY_LIMIT_MB) a million polar decompositions (216 MB) and
// three 2000 x 2000 matrices (96 MB) are refused when the options are read.
TEST(CliOptions, SizesBeyondTheMemoryAreRefusedNamingTheMostThatFit) {
  const fs::path dir = dgtex::test::fresh_dir("dgtex_cli_options", "memory");
  const Refusal refusals[] = {
      {"bench scaling --families polar_decomposition --polar-count 1000000 --repeats 1",
       "dgtex bench scaling: --polar-count: 1000000 matrices (216 bytes each) would not fit the 64 MiB of memory "
       "available; expected at most "},
      {"bench shell --gemm-size 2000",
       "dgtex bench shell: --gemm-size: 2000: three n x n matrices would not fit the 64 MiB of memory available; "
       "expected at most "},
  };
  for (const Refusal& refusal : refusals) {
    const CliResult r = run_cli(refusal.args, dir, "DGTEX_MEMORY_LIMIT_MB=64");
    EXPECT_EQ(r.exit_code, 2) << refusal.args << ": " << r.stderr_text;
    EXPECT_EQ(r.stderr_text.rfind(refusal.message_start, 0), 0u) << r.stderr_text;
    // A limit that is no number is bad input too (the check's exception aborted the process).
    const CliResult bad = run_cli(refusal.args, dir, "DGTEX_MEMORY_LIMIT_MB=abc");
    EXPECT_EQ(bad.exit_code, 2) << refusal.args << ": " << bad.stderr_text;
    EXPECT_NE(bad.stderr_text.find(": DGTEX_MEMORY_LIMIT_MB = 'abc': expected a whole number of MiB"), std::string::npos)
        << bad.stderr_text;
  }
}

// An empty --out must not make the working folder the output folder: run there, nothing
// appears in it.
TEST(CliOptions, AnEmptyOutputFolderWritesNothingIntoTheWorkingFolder) {
  const fs::path dir = dgtex::test::fresh_dir("dgtex_cli_options", "empty_out");
  const fs::path work = dir / "work";
  fs::create_directories(work);
  const CliResult r =
      run_cli("run " + kScenes + "/clamped_plate.json --out '' --quiet --no-render", dir, "cd " + work.string() + " &&");
  EXPECT_EQ(r.exit_code, 2) << r.stderr_text;
  EXPECT_TRUE(fs::is_empty(work));
}

// A failed write is a failure: the JSON and Markdown were buffered and never flushed, so a
// full disk (/dev/full) ended the command with exit code 0.
TEST(CliOptions, AWriteThatFailsEndsWithExitCodeOne) {
  const fs::path dir = dgtex::test::fresh_dir("dgtex_cli_options", "full");
  for (const char* option : {"--json", "--markdown"}) {
    const CliResult r = run_cli(std::string("bench scaling --families polar_decomposition --polar-count 1000 --repeats 1 "
                                            "--threads-list 1 ") +
                                    option + " /dev/full",
                                dir);
    EXPECT_EQ(r.exit_code, 1) << option << ": " << r.stderr_text;
    EXPECT_NE(r.stderr_text.find(std::string("cannot write ") + option + " file '/dev/full'"), std::string::npos)
        << r.stderr_text;
  }
}

// An output given the path of an input replaced it: `bench shell --scene s.json --json
// s.json` left results where the scene was, `render s.png --out s.png` the image where
// the state was, and `run r/final.state --out r` (a scene saved under an output's name)
// deleted its own scene when it cleared the earlier run's files. Each is refused before
// anything is written, the input unchanged.
TEST(CliOptions, OutputsNeverReplaceInputs) {
  const fs::path dir = dgtex::test::fresh_dir("dgtex_cli_options", "inputs");
  const std::string scene = (dir / "scene.json").string(), saved = (dir / "final.state").string();
  const std::string cylinder = kScenes + "/cylinder_buckling.json";
  for (const std::string& copy : {scene, saved, (dir / "s.png").string()})
    fs::copy_file(cylinder, copy, fs::copy_options::overwrite_existing);
  const Refusal refusals[] = {
      {"bench shell --scene DIR/scene.json --json DIR/scene.json",
       "dgtex bench shell: --json 'DIR/scene.json' is the scene of --scene 'DIR/scene.json'; give the output another "
       "file"},
      {"bench scaling --families batch --batch-scenes DIR/scene.json --markdown DIR/./scene.json",
       "dgtex bench scaling: --markdown 'DIR/./scene.json' is a scene of --batch-scenes"},
      {"bench scenes --scenes DIR/scene.json --json DIR/scene.json", "dgtex bench scenes: --json 'DIR/scene.json' is a "
                                                                     "scene of --scenes"},
      {"render DIR/s.png --out DIR/s.png", "dgtex render: --out 'DIR/s.png' is the state file"},
      {"run DIR/final.state --out DIR", "dgtex run: DIR/final.state: --out DIR: the run writes or clears "
                                        "'DIR/final.state', the scene file; choose another output folder"},
  };
  for (const Refusal& refusal : refusals) {
    std::string args = refusal.args, expected = refusal.message_start;
    for (std::string* text : {&args, &expected})
      for (std::size_t at = text->find("DIR"); at != std::string::npos; at = text->find("DIR", at))
        text->replace(at, 3, dir.string());
    const CliResult r = run_cli(args, dir);
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.stderr_text;
    EXPECT_EQ(r.stderr_text.rfind(expected, 0), 0u) << args << ": " << r.stderr_text;
  }
  const std::string original = dgtex::test::file_text(cylinder);
  for (const std::string& copy : {scene, saved, (dir / "s.png").string()})
    EXPECT_EQ(dgtex::test::file_text(copy), original) << copy;
}

// `bench scenes` read each scene when it came to it: a static scene after a dynamic one
// ended the command after the first one's runs, with a partial table. All are read first.
TEST(CliOptions, BenchScenesReadsEverySceneBeforeTheFirstRuns) {
  const fs::path dir = dgtex::test::fresh_dir("dgtex_cli_options", "scenes_first");
  const CliResult r = run_cli("bench scenes --quiet --steps 1 --scenes " + kScenes + "/cylinder_buckling.json," + kScenes +
                                  "/clamped_plate.json --json " + (dir / "t.json").string(),
                              dir);
  EXPECT_EQ(r.exit_code, 2) << r.stderr_text;
  EXPECT_EQ(r.stderr_text.rfind("dgtex bench scenes: --scenes: scene '" + kScenes + "/clamped_plate.json' is a static analysis", 0),
            0u)
      << r.stderr_text;
  EXPECT_FALSE(fs::exists(dir / "t.json"));  // nothing ran
}

// The top level's own mistakes: "--version extra" read as an unknown command named
// "--version", "dgtex bench" alone as a benchmark named '', an empty scene path as ": cannot
// read the scene file".
TEST(CliOptions, TopLevelMistakesNameWhatWasWrong) {
  const fs::path dir = dgtex::test::fresh_dir("dgtex_cli_options", "top_level");
  const Refusal refusals[] = {
      {"--version extra", "dgtex: --version takes no arguments, got 'extra'"},
      {"bench", "dgtex bench: which benchmark? (valid: laplace, shell, render, scenes, scaling, accuracy)"},
      {"run '' --out DIR/o", "dgtex run: '': an empty scene file path; give a scene file (JSON)"},
  };
  for (const Refusal& refusal : refusals) {
    std::string args = refusal.args;
    if (const std::size_t at = args.find("DIR"); at != std::string::npos) args.replace(at, 3, dir.string());
    const CliResult r = run_cli(args, dir);
    EXPECT_EQ(r.exit_code, 2) << args << ": " << r.stderr_text;
    EXPECT_EQ(r.stderr_text, std::string(refusal.message_start) + "\n") << args;
  }
}

TEST(CliOptions, BenchHelpListsTheBenchmarks) {
  const fs::path dir = dgtex::test::fresh_dir("dgtex_cli_options", "help");
  const CliResult r = run_cli("bench --help", dir);
  EXPECT_EQ(r.exit_code, 0) << r.stderr_text;
  EXPECT_EQ(r.stderr_text, "");
}

}  // namespace
