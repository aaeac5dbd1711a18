// dgtex bench accuracy (dgtex/accuracy_benchmark.h): a reduced run through the CLI, with
// invariants that a broken sweep would violate (convergence with refinement and texture
// resolution, the per-texel reference, error bounds of loose tolerances), the output files
// and keys, and the rejection of bad arguments.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "dgtex/accuracy_benchmark.h"
#include "dgtex/version.h"

namespace {

namespace fs = std::filesystem;

// Points of one chart: series -> points in run order.
std::map<std::string, std::vector<nlohmann::json>> by_series(const nlohmann::json& chart) {
  std::map<std::string, std::vector<nlohmann::json>> out;
  for (const auto& p : chart.at("points")) out[p.at("series").get<std::string>()].push_back(p);
  return out;
}

// The reduced run (once per test process; gtest_discover_tests runs each TEST alone, so
// all checks of it live in one TEST).
struct ReducedRun {
  fs::path dir;
  int status = -1;
  nlohmann::json json;
  const nlohmann::json& chart(const std::string& name) const {
    for (const auto& c : json.at("charts"))
      if (c.at("name") == name) return c;
    ADD_FAILURE() << "no chart " << name;
    static const nlohmann::json empty = {{"points", nlohmann::json::array()}};
    return empty;
  }
};

ReducedRun run_reduced() {
  ReducedRun run;
  run.dir = fs::temp_directory_path() / ("dgtex_bench_accuracy_" + std::to_string(getpid()));
  fs::remove_all(run.dir);
  const std::string command =
      std::string(DGTEX_CLI) +
      " bench accuracy --threads 1 --repeat 1 --plate-divisions 4,8,16 --quadrature-resolution 32"
      " --quadrature-tolerances 1,1e-2 --texture-sizes 16,32,64 --shell-scene " DGTEX_SOURCE_DIR
      "/examples/scenes/cylinder_buckling.json --shell-steps 3 --shell-tolerances 1e-2,1e-8 --multigrid-size 64"
      " --multigrid-tolerances 1e-1,1e-8 --rotation-scene " DGTEX_SOURCE_DIR
      "/examples/scenes/accordion.json --rotation-steps 3 --rotation-blocks 64,32"
      " --scene-quadrature-scene " DGTEX_SOURCE_DIR
      "/examples/scenes/spiral1.json --scene-quadrature-steps 5 --scene-quadrature-tolerances 1,0.1"
      " --scene-quadrature-reference 1e-3 --out " +
      run.dir.string() + " > " + (run.dir.string() + ".log") + " 2>&1";
  run.status = std::system(command.c_str());
  std::ifstream in(run.dir / "accuracy.json");
  if (in) in >> run.json;
  return run;
}

void check_WritesChartsJsonAndTable(const ReducedRun& run) {
  SCOPED_TRACE("WritesChartsJsonAndTable");
  for (const char* name : {"plate", "quadrature", "texture", "tolerance", "rotation", "scene_quadrature"}) {
    EXPECT_TRUE(fs::exists(run.dir / (std::string("accuracy_") + name + ".png"))) << name;
    const auto& c = run.chart(name);
    for (const char* key : {"title", "time_label", "error_label", "points"}) EXPECT_TRUE(c.contains(key)) << name << key;
    ASSERT_FALSE(c.at("points").empty()) << name;
    for (const auto& p : c.at("points")) {
      for (const char* key : {"series", "label", "ms", "error"}) EXPECT_TRUE(p.contains(key)) << name << " " << key;
      EXPECT_GT(p.at("ms").get<double>(), 0.0);  // measured
      EXPECT_TRUE(std::isfinite(p.at("error").get<double>()));
      // Counts are JSON integers ("n": 2 was written 2.0).
      for (const char* key : {"n", "T", "free_dofs", "iterations", "pcg_iterations", "factorizations", "clusters",
                              "texels", "unknowns", "quadrature_points"}) {
        if (p.contains(key)) {
          EXPECT_TRUE(p.at(key).is_number_integer()) << name << " " << key << " " << p.at(key);
        }
      }
    }
  }
  EXPECT_TRUE(run.chart("plate").at("points").at(0).contains("free_dofs"));
  EXPECT_FALSE(run.json.at("machine").get<std::string>().empty());
  EXPECT_EQ(run.json.at("dgtex_version"), dgtex::version());
  EXPECT_NE(run.json.at("command").get<std::string>().find("dgtex bench accuracy"), std::string::npos);
  EXPECT_TRUE(fs::exists(run.dir / "accuracy.md"));
}

// Simply supported plate: the centre deflection error falls with every refinement, at a
// rate of at least 1.5 from n = 8 to 16 (measured: quad8 2.09, tri6 1.86).
void check_PlateErrorConvergesWithRefinement(const ReducedRun& run) {
  SCOPED_TRACE("PlateErrorConvergesWithRefinement");
  const auto series = by_series(run.chart("plate"));
  ASSERT_EQ(series.size(), 2u);
  for (const auto& [name, points] : series) {
    ASSERT_EQ(points.size(), 3u) << name;
    for (std::size_t k = 1; k < points.size(); ++k)
      EXPECT_LT(points[k].at("error").get<double>(), points[k - 1].at("error").get<double>()) << name;
    const double rate = std::log2(points[1].at("error").get<double>() / points[2].at("error").get<double>());
    EXPECT_GT(rate, 1.5) << name;
    EXPECT_LT(points[2].at("error").get<double>(), name == "quad8" ? 5e-3 : 2e-2) << name;
  }
}

// The per-texel rule is the reference (error exactly 0) and has the most points; a merge
// tolerance of 1e-2 stays within 2 % of its compliance, even the loosest (1) within 10 %.
void check_QuadratureReferenceAndBounds(const ReducedRun& run) {
  SCOPED_TRACE("QuadratureReferenceAndBounds");
  const auto series = by_series(run.chart("quadrature"));
  ASSERT_EQ(series.size(), 2u);
  for (const auto& [name, points] : series) {
    ASSERT_EQ(points.size(), 3u) << name;
    EXPECT_EQ(points[0].at("label"), "per-texel");
    EXPECT_EQ(points[0].at("error").get<double>(), 0.0);
    const double reference_points = points[0].at("quadrature_points").get<double>();
    EXPECT_LT(points[1].at("quadrature_points").get<double>(), points[2].at("quadrature_points").get<double>()) << name;
    EXPECT_LT(points[2].at("quadrature_points").get<double>(), reference_points) << name;
    EXPECT_LT(points[1].at("error").get<double>(), 0.1) << name << " tol=1";
    EXPECT_LT(points[2].at("error").get<double>(), 0.02) << name << " tol=1e-2";
  }
}

// Crack tip: the error in the fixed annulus falls with T; CHOLMOD and the multigrid (to
// 1e-10) give the same field, so the same error to 1e-6.
void check_TipErrorFallsWithTextureResolution(const ReducedRun& run) {
  SCOPED_TRACE("TipErrorFallsWithTextureResolution");
  const auto series = by_series(run.chart("texture"));
  ASSERT_EQ(series.size(), 2u);
  for (const auto& [name, points] : series) {
    ASSERT_EQ(points.size(), 3u) << name;
    for (std::size_t k = 1; k < points.size(); ++k)
      EXPECT_LT(points[k].at("error").get<double>(), 0.8 * points[k - 1].at("error").get<double>()) << name;
  }
  const auto& cholmod = series.at("CHOLMOD");
  const auto& multigrid = series.at("multigrid");
  for (std::size_t k = 0; k < cholmod.size(); ++k)
    EXPECT_NEAR(cholmod[k].at("error").get<double>(), multigrid[k].at("error").get<double>(), 1e-6);
}

// Tolerances: the references have error 0; the shell's loosest PCG tolerance (1e-2, 3
// steps) stays within 1e-3 of factorising every step and the default-class one (1e-8)
// within 1e-6; the multigrid at 1e-1 is within 0.1 of CHOLMOD (H in [-1, 1]) and at 1e-8
// within 1e-6.
void check_ToleranceErrorsWithinBounds(const ReducedRun& run) {
  SCOPED_TRACE("ToleranceErrorsWithinBounds");
  const auto series = by_series(run.chart("tolerance"));
  ASSERT_EQ(series.size(), 2u);
  for (const auto& [name, points] : series) {
    ASSERT_EQ(points.size(), 3u) << name;
    EXPECT_EQ(points[0].at("error").get<double>(), 0.0) << name;
    const bool shell = name.rfind("shell", 0) == 0;
    EXPECT_LT(points[1].at("error").get<double>(), shell ? 1e-3 : 0.1) << name;
    EXPECT_LT(points[2].at("error").get<double>(), 1e-6) << name;
    EXPECT_LE(points[2].at("error").get<double>(), points[1].at("error").get<double>()) << name;
  }
}

// Rotation clusters: per point is the reference (error 0); blocks of 64 and 32 texels stay
// within 1 % of it over the accordion's first 3 steps (measured: 1.4e-3 and 6.3e-4), and
// the smaller blocks make more clusters.
void check_RotationClustersWithinBounds(const ReducedRun& run) {
  SCOPED_TRACE("RotationClustersWithinBounds");
  const auto series = by_series(run.chart("rotation"));
  ASSERT_EQ(series.size(), 1u);
  const auto& points = series.begin()->second;
  ASSERT_EQ(points.size(), 3u);
  EXPECT_EQ(points[0].at("label"), "per point");
  EXPECT_EQ(points[0].at("error").get<double>(), 0.0);
  EXPECT_EQ(points[0].at("clusters").get<double>(), 0.0);
  for (std::size_t k = 1; k < 3; ++k) {
    EXPECT_GT(points[k].at("error").get<double>(), 0.0) << k;
    EXPECT_LT(points[k].at("error").get<double>(), 0.01) << k;
    EXPECT_GT(points[k].at("cluster_mb").get<double>(), 0.0) << k;
  }
  EXPECT_GT(points[2].at("clusters").get<double>(), points[1].at("clusters").get<double>());
}

// A scene's merge tolerance: the reference tolerance has error 0 and the most points; over
// spiral1's first 5 steps tolerance 1 stays within 1 % of it and 0.1 within 1e-3
// (measured: 1.6e-3 and 1.9e-5), fewer points giving the larger error. The time-step point
// is the scene's own tolerance (0.1, that run reused) against half the time step.
void check_SceneQuadratureWithinBounds(const ReducedRun& run) {
  SCOPED_TRACE("SceneQuadratureWithinBounds");
  const auto series = by_series(run.chart("scene_quadrature"));
  ASSERT_EQ(series.size(), 2u);
  const auto& sweep = series.at("spiral1.json, against tol=0.001");
  ASSERT_EQ(sweep.size(), 3u);
  EXPECT_EQ(sweep[0].at("label"), "tol=0.001");
  EXPECT_EQ(sweep[0].at("error").get<double>(), 0.0);
  EXPECT_LT(sweep[1].at("quadrature_points").get<double>(), sweep[2].at("quadrature_points").get<double>());
  EXPECT_LT(sweep[2].at("quadrature_points").get<double>(), sweep[0].at("quadrature_points").get<double>());
  EXPECT_LT(sweep[1].at("error").get<double>(), 0.01);
  EXPECT_GT(sweep[2].at("error").get<double>(), 0.0);
  EXPECT_LT(sweep[2].at("error").get<double>(), 1e-3);
  EXPECT_LT(sweep[2].at("error").get<double>(), sweep[1].at("error").get<double>());
  // The largest difference over the steps: 0 for the reference itself, small for the others
  // (measured: 1.9e-3 and 1.9e-5).
  EXPECT_EQ(sweep[0].at("worst_error_in_run").get<double>(), 0.0);
  for (std::size_t k = 1; k < 3; ++k) {
    EXPECT_GT(sweep[k].at("worst_error_in_run").get<double>(), 0.0) << k;
    EXPECT_LT(sweep[k].at("worst_error_in_run").get<double>(), 0.05) << k;
  }
  const auto& time_step = series.at("spiral1.json, time step against half of it");
  ASSERT_EQ(time_step.size(), 1u);
  EXPECT_EQ(time_step[0].at("label"), "tol=0.1 (the scene's)");
  EXPECT_GT(time_step[0].at("error").get<double>(), 0.0);
  EXPECT_EQ(time_step[0].at("ms").get<double>(), sweep[2].at("ms").get<double>());
  // Both swept tolerances stay below the time-step error (0.12 over 5 steps): the
  // conclusion names the larger one, in the JSON and below the Markdown table.
  const std::string expected = "below the time-step error at the end and over the run: 1 (";
  ASSERT_TRUE(run.chart("scene_quadrature").contains("conclusion"));
  EXPECT_NE(run.chart("scene_quadrature").at("conclusion").get<std::string>().find(expected), std::string::npos);
  std::ifstream table(run.dir / "accuracy.md");
  const std::string text((std::istreambuf_iterator<char>(table)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find(expected), std::string::npos);
  EXPECT_FALSE(run.chart("rotation").contains("conclusion"));  // the other sweeps conclude nothing
}

TEST(BenchAccuracy, ReducedRunMeetsInvariants) {
  const ReducedRun run = run_reduced();
  ASSERT_EQ(run.status, 0) << "see " << run.dir.string() << ".log";
  check_WritesChartsJsonAndTable(run);
  check_PlateErrorConvergesWithRefinement(run);
  check_QuadratureReferenceAndBounds(run);
  check_TipErrorFallsWithTextureResolution(run);
  check_ToleranceErrorsWithinBounds(run);
  check_RotationClustersWithinBounds(run);
  check_SceneQuadratureWithinBounds(run);
  fs::remove_all(run.dir);
  fs::remove(run.dir.string() + ".log");
}

TEST(BenchAccuracyArguments, BadValuesAreRejectedWithExitCode2) {
  const std::string cli = DGTEX_CLI;
  const std::string out = (fs::temp_directory_path() / ("dgtex_bench_accuracy_bad_" + std::to_string(getpid()))).string();
  EXPECT_EQ(WEXITSTATUS(std::system((cli + " bench accuracy --charts plate,bogus --out " + out + " 2>/dev/null").c_str())), 2);
  EXPECT_EQ(WEXITSTATUS(std::system((cli + " bench accuracy --charts plate --plate-divisions 3 --out " + out +
                                     " 2>/dev/null").c_str())), 2);
  // Past 256 the plate's system and factor outgrow memory: refused up front (a bare
  // std::bad_alloc and exit code 1 before).
  EXPECT_EQ(WEXITSTATUS(std::system((cli + " bench accuracy --charts plate --plate-divisions 100000 --out " + out +
                                     " 2>/dev/null").c_str())), 2);
  EXPECT_EQ(WEXITSTATUS(std::system((cli + " bench accuracy --charts texture --texture-sizes 8 --out " + out +
                                     " 2>/dev/null").c_str())), 2);
  // Rotation clusters need cuts: a scene without gave error 0 everywhere, and the log-scale
  // chart then failed as if gnuplot were missing (exit code 1).
  EXPECT_EQ(WEXITSTATUS(std::system((cli + " bench accuracy --charts rotation --rotation-scene " + DGTEX_SOURCE_DIR +
                                     "/examples/scenes/cylinder_buckling.json --out " + out + " 2>/dev/null").c_str())),
            2);
  // So does the merge tolerance of a scene's enriched quadrature; and tolerances must be > 0.
  EXPECT_EQ(WEXITSTATUS(std::system((cli + " bench accuracy --charts scene_quadrature --scene-quadrature-scene " +
                                     DGTEX_SOURCE_DIR + "/examples/scenes/cylinder_buckling.json --out " + out +
                                     " 2>/dev/null").c_str())),
            2);
  EXPECT_EQ(WEXITSTATUS(std::system((cli + " bench accuracy --charts scene_quadrature --scene-quadrature-tolerances 0"
                                     " --out " + out + " 2>/dev/null").c_str())),
            2);
  // The shell tolerance sweep's scene is checked up front, chosen or not: a scene with cuts
  // (or one that did not load) ended the command with exit code 1 after the other sweeps,
  // and passed unread with --charts plate (helper audit, session 71).
  for (const char* charts : {"tolerance", "plate"})
    EXPECT_EQ(WEXITSTATUS(std::system((cli + " bench accuracy --charts " + charts + " --shell-scene " + DGTEX_SOURCE_DIR +
                                       "/examples/scenes/spiral1.json --out " + out + " 2>/dev/null").c_str())),
              2)
        << charts;
  fs::remove_all(out);
}

// A sweep whose every run equals its reference (error 0, which a log scale cannot place)
// still gets its chart: before, gnuplot found no point to scale by and the command failed
// as if gnuplot were missing (exit code 1).
TEST(BenchAccuracyCharts, EveryErrorZeroStillDrawsTheChart) {
  const fs::path out = fs::temp_directory_path() / ("dgtex_bench_accuracy_zero_" + std::to_string(getpid()));
  const std::string command = std::string(DGTEX_CLI) +
                              " bench accuracy --charts scene_quadrature --threads 1 --scene-quadrature-scene " +
                              DGTEX_SOURCE_DIR + "/examples/scenes/spiral1.json --scene-quadrature-steps 2"
                              " --scene-quadrature-tolerances 1e-2 --scene-quadrature-reference 1e-2"
                              " --no-time-step-error --out " + out.string() + " > /dev/null 2>&1";
  EXPECT_EQ(WEXITSTATUS(std::system(command.c_str())), 0);
  ASSERT_TRUE(fs::exists(out / "accuracy_scene_quadrature.png"));
  EXPECT_GT(fs::file_size(out / "accuracy_scene_quadrature.png"), 0u);
  fs::remove_all(out);
}

// A second run into the same folder leaves none of the first run's charts beside its own
// JSON (a texture chart stayed there after a plate-only run), and never clears a scene it
// reads: a --shell-scene saved there as accuracy.json is refused before anything is written.
TEST(BenchAccuracyCharts, AnEarlierRunsChartsGoAndInputsStay) {
  const fs::path out = fs::temp_directory_path() / ("dgtex_bench_accuracy_again_" + std::to_string(getpid()));
  fs::remove_all(out);
  fs::create_directories(out);
  std::ofstream(out / "accuracy_texture.png") << "an earlier run's chart";
  std::ofstream(out / "notes.txt") << "the user's";
  const std::string plate_only = std::string(DGTEX_CLI) + " bench accuracy --charts plate --plate-divisions 2 --repeat 1 "
                                 "--out " + out.string();
  EXPECT_EQ(WEXITSTATUS(std::system((plate_only + " > /dev/null 2>&1").c_str())), 0);
  EXPECT_FALSE(fs::exists(out / "accuracy_texture.png"));
  EXPECT_TRUE(fs::exists(out / "accuracy_plate.png"));
  EXPECT_TRUE(fs::exists(out / "notes.txt"));  // not a name it writes
  fs::copy_file(std::string(DGTEX_SOURCE_DIR) + "/examples/scenes/cylinder_buckling.json", out / "accuracy.json",
                fs::copy_options::overwrite_existing);
  const std::string reads_it = plate_only + " --shell-scene " + (out / "accuracy.json").string() + " 2> " +
                               (out / "err.txt").string();
  EXPECT_EQ(WEXITSTATUS(std::system(reads_it.c_str())), 2);
  std::ifstream err(out / "err.txt");
  const std::string message((std::istreambuf_iterator<char>(err)), std::istreambuf_iterator<char>());
  EXPECT_NE(message.find("the run writes or clears '" + (out / "accuracy.json").string() + "', the scene of --shell-scene"),
            std::string::npos)
      << message;
  std::ifstream kept(out / "accuracy.json");
  EXPECT_NE(std::string((std::istreambuf_iterator<char>(kept)), std::istreambuf_iterator<char>()).find("\"analysis\""),
            std::string::npos);
  EXPECT_TRUE(fs::exists(out / "accuracy_plate.png"));  // nothing cleared
  fs::remove_all(out);
}

// The Navier series gives Timoshenko's 0.00406 q a^4 / D for the square plate (nu-free).
TEST(BenchAccuracyNavier, SquarePlateCoefficient) {
  const double D = 2.0, q = -3.0, a = 1.5;
  const double w = dgtex::navier_plate_centre_deflection(a, a, q, D);
  EXPECT_NEAR(w * D / (q * std::pow(a, 4)), 0.0040623527, 1e-9);
  // A 2:1 rectangle: Timoshenko Table 8 gives 0.01013 for b = 2a.
  EXPECT_NEAR(dgtex::navier_plate_centre_deflection(1, 2, 1, 1), 0.01013, 5e-5);
}

// The texture error helper used by the chart: falls with T (2.7e-2 at T = 16).
TEST(BenchAccuracyTexture, HelperErrorFallsWithResolution) {
  const double e16 = dgtex::crack_tip_texture_error(16), e32 = dgtex::crack_tip_texture_error(32);
  EXPECT_LT(e16, 0.05);
  EXPECT_LT(e32, 0.8 * e16);
  EXPECT_THROW(dgtex::crack_tip_texture_error(15), std::invalid_argument);
}

}  // namespace
