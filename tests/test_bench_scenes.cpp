// dgtex bench scenes (dgtex/scene_benchmark.h): the JSON holds every requested scene with
// the required keys, counts its steps, reports the same model sizes as `dgtex run`, and
// the benchmark does not change the simulation it times. Few steps of cheap scenes only.
#include <gtest/gtest.h>

#include <omp.h>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <set>
#include <string>

#include "cli_test_support.h"
#include "dgtex/scene_benchmark.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"
#include "dgtex/version.h"

namespace fs = std::filesystem;
using namespace dgtex;

namespace {

const std::string kScenes = std::string(DGTEX_SOURCE_DIR) + "/examples/scenes";

using Result = test::CliResult;
using test::run_cli;

fs::path fresh_dir(const std::string& name) { return test::fresh_dir("dgtex_bench_scenes", name); }

nlohmann::json read_json(const fs::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

// spiral1 with its own step count set to `steps` and no render block, written to dir.
fs::path short_spiral(const fs::path& dir, int steps) {
  nlohmann::json scene = read_json(kScenes + "/spiral1.json");
  scene["analysis"]["steps"] = steps;
  scene.erase("render");
  const fs::path path = dir / "spiral1.json";
  std::ofstream(path) << scene.dump(2);
  return path;
}

}  // namespace

TEST(BenchScenes, JsonHasEveryRequestedSceneWithRequiredKeysAndThesisRatios) {
  const fs::path dir = fresh_dir("json");
  const Result r = run_cli("bench scenes --scene-dir " + kScenes + " --scenes spiral1,cylinder_buckling --steps 2 --json " +
                               (dir / "out.json").string() + " --markdown " + (dir / "out.md").string() +
                               " --cut-update-threads 1 --quiet",
                           dir);
  ASSERT_EQ(r.exit_code, 0) << r.stderr_text;
  const nlohmann::json j = read_json(dir / "out.json");
  EXPECT_EQ(j["cut_update_threads"], 1);
  EXPECT_EQ(j["reserve_step_memory"], true);  // the default (dgtex/step_memory.h)
  ASSERT_EQ(j["scenes"].size(), 2u);
  // The machine, and its speed probes (one core, every thread at once) before each scene's
  // run and at the end.
  EXPECT_NE(j["machine"].get<std::string>().find(" cores, "), std::string::npos);
  EXPECT_EQ(j["dgtex_version"], dgtex::version());
  EXPECT_GT(j["machine_probe_ms_at_end"].get<double>(), 0);
  EXPECT_GT(j["machine_probe_all_threads_ms_at_end"].get<double>(), 0);
  for (const nlohmann::json& s : j["scenes"]) {
    EXPECT_GT(s["machine_probe_ms"].get<double>(), 0);
    EXPECT_GT(s["machine_probe_all_threads_ms"].get<double>(), 0);
  }
  EXPECT_EQ(j["scenes"][0]["name"], "spiral1");
  EXPECT_EQ(j["scenes"][1]["name"], "cylinder_buckling");
  for (const nlohmann::json& s : j["scenes"]) {
    EXPECT_EQ(s["steps"], 2);
    EXPECT_GT(s["steps_per_second"].get<double>(), 0);
    for (const char* stage : {"enrichment", "assembly", "solve"}) {
      ASSERT_TRUE(s["timings_ms"].contains(stage)) << stage;
      const double mean = s["timings_ms"][stage]["mean"], max = s["timings_ms"][stage]["max"];
      EXPECT_GE(mean, 0) << stage;
      EXPECT_GE(max, mean) << stage;
      EXPECT_EQ(s["per_step_ms"][stage].size(), 2u) << stage;
    }
    EXPECT_GT(s["timings_ms"]["assembly"]["mean"].get<double>(), 0);
    EXPECT_GT(s["timings_ms"]["solve"]["mean"].get<double>(), 0);
    // steps/s is the inverse of the mean whole-step time.
    EXPECT_NEAR(s["steps_per_second"].get<double>() * s["timings_ms"]["step"]["mean"].get<double>(), 1e3, 1e-6);
    // The steps slower than the peak-step target (30 steps/s), counted from the steps' times.
    int slower = 0;
    for (const nlohmann::json& ms : s["per_step_ms"]["step"]) slower += 1e3 / ms.get<double>() < 30;
    EXPECT_EQ(s["steps_slower_than_target"].get<int>(), slower);
    for (const char* key : {"elements", "nodes", "dofs", "free_dofs", "nonzeros", "enrichments"})
      EXPECT_TRUE(s["counts"].contains(key)) << key;
    // The solver's counts per step add up to the totals; the first step factorises, and
    // under gravity every step iterates.
    const nlohmann::json& solver = s["solver"]["per_step"];
    ASSERT_EQ(solver["pcg_iterations"].size(), 2u);
    ASSERT_EQ(solver["factorizations"].size(), 2u);
    EXPECT_GE(solver["factorizations"][0].get<int>(), 1);
    EXPECT_GE(solver["pcg_iterations"][0].get<int>(), 1);
    EXPECT_GE(solver["pcg_iterations"][1].get<int>(), 1);
    EXPECT_EQ(s["solver"]["pcg_iterations"].get<int>(),
              solver["pcg_iterations"][0].get<int>() + solver["pcg_iterations"][1].get<int>());
    EXPECT_EQ(s["solver"]["factorizations"].get<int>(),
              solver["factorizations"][0].get<int>() + solver["factorizations"][1].get<int>());
    // Nothing runs beside the first step, nor beside a scene's last (here 2 steps of 300 and 50).
    ASSERT_EQ(s["cut_update_threads"]["per_step"].size(), 2u);
    EXPECT_EQ(s["cut_update_threads"]["per_step"][0], 0);
    EXPECT_LE(s["cut_update_threads"]["steps_beside"].get<int>(), 1);
  }
  // spiral1: Table 5.1 "Spiral 1" (274 / 1.8 / 0.1 ms); ratio = thesis / ours.
  const nlohmann::json& spiral = j["scenes"][0];
  EXPECT_EQ(spiral["table_5_1"]["model"], "Spiral 1");
  EXPECT_NEAR(spiral["ratio_to_table_5_1"]["enrichment"].get<double>() * spiral["timings_ms"]["enrichment"]["max"].get<double>(),
              274.0, 1e-9);
  EXPECT_NEAR(spiral["ratio_to_table_5_1"]["assembly"].get<double>() * spiral["timings_ms"]["assembly"]["mean"].get<double>(),
              1.8, 1e-12);
  EXPECT_NEAR(spiral["ratio_to_table_5_1"]["solve"].get<double>() * spiral["timings_ms"]["solve"]["mean"].get<double>(),
              0.1, 1e-12);
  EXPECT_EQ(spiral["counts"]["elements"], 1);
  EXPECT_EQ(spiral["counts"]["nodes"], 8);
  // The settings its speed depends on, as its scene file sets them (spiral1: dt 1e-3, merge
  // tolerance 0.1, rotation blocks of 16 texels; the cylinder: per point).
  EXPECT_EQ(spiral["accuracy_settings"]["time_step"].get<double>(), 1e-3);
  EXPECT_EQ(spiral["accuracy_settings"]["quadrature_tolerance"].get<double>(), 0.1);
  EXPECT_EQ(spiral["accuracy_settings"]["rotation_cluster_texels"].get<int>(), 16);
  EXPECT_EQ(j["scenes"][1]["accuracy_settings"]["rotation_cluster_texels"].get<int>(), 0);
  // 2 of the scene's 300 steps: the targets (whole-run means in Table 5.1) are not judged.
  EXPECT_TRUE(spiral["targets_met"].is_null());
  EXPECT_TRUE(spiral["targets_missed"].is_null());
  EXPECT_TRUE(j["scenes"][1]["table_5_1"].is_null());
  EXPECT_TRUE(j["scenes"][1]["ratio_to_table_5_1"].is_null());
  // No row, no targets: the keys are there, null (they were left out).
  ASSERT_TRUE(j["scenes"][1].contains("targets_met"));
  ASSERT_TRUE(j["scenes"][1].contains("targets_missed"));
  EXPECT_TRUE(j["scenes"][1]["targets_met"].is_null());
  EXPECT_TRUE(j["scenes"][1]["targets_missed"].is_null());
  EXPECT_EQ(j["scenes"][1]["counts"]["enrichments"], 0);
  // The Markdown file starts with the same heading as the printed tables: machine and probe.
  std::ifstream markdown(dir / "out.md");
  std::string heading;
  std::getline(markdown, heading);
  EXPECT_EQ(heading.rfind("dgtex bench scenes: " + j["machine"].get<std::string>() + ";", 0), 0u) << heading;
  EXPECT_NE(heading.find("machine probe "), std::string::npos) << heading;
  const std::string all_threads = " ms (each of " + std::to_string(j["threads"].get<int>()) + " threads at once)";
  EXPECT_NE(heading.find(all_threads), std::string::npos) << heading;
  std::string text((std::istreambuf_iterator<char>(markdown)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("| 0.001 / 0.1 / 16 |"), std::string::npos) << text;
  EXPECT_NE(text.find(" / per point |"), std::string::npos) << text;
  EXPECT_EQ(text.find("run by run"), std::string::npos) << "one run: no table of every run\n" << text;
}

// --repeats: every run of a scene is listed; the tables and the scene's own keys are the
// fastest whole run's; the runs end in bitwise the same state.
TEST(BenchScenes, RepeatsShowTheFastestRunAndListEveryRun) {
  const fs::path dir = fresh_dir("repeats");
  const Result r = run_cli("bench scenes --scene-dir " + kScenes + " --scenes spiral1 --steps 2 --repeats 3 --json " +
                               (dir / "out.json").string() + " --markdown " + (dir / "out.md").string() +
                               " --no-memory-reserve --quiet",
                           dir);
  ASSERT_EQ(r.exit_code, 0) << r.stderr_text;
  const nlohmann::json j = read_json(dir / "out.json");
  EXPECT_EQ(j["repeats"], 3);
  EXPECT_EQ(j["reserve_step_memory"], false);
  ASSERT_EQ(j["scenes"].size(), 1u);
  const nlohmann::json& scene = j["scenes"][0];
  const nlohmann::json& runs = scene["runs"];
  EXPECT_EQ(runs["count"], 3);
  for (const char* key : {"steps_per_second", "peak_step_ms", "steps_slower_than_target", "enrichment_ms_max",
                          "machine_probe_ms", "machine_probe_all_threads_ms"})
    ASSERT_EQ(runs[key].size(), 3u) << key;
  const std::size_t shown = runs["shown"].get<std::size_t>();
  ASSERT_LT(shown, 3u);
  for (const nlohmann::json& other : runs["steps_per_second"])
    EXPECT_GE(runs["steps_per_second"][shown].get<double>(), other.get<double>());
  EXPECT_EQ(scene["steps_per_second"].get<double>(), runs["steps_per_second"][shown].get<double>());
  EXPECT_EQ(scene["peak_step_ms"].get<double>(), runs["peak_step_ms"][shown].get<double>());
  EXPECT_EQ(scene["steps_slower_than_target"].get<int>(), runs["steps_slower_than_target"][shown].get<int>());
  EXPECT_EQ(scene["timings_ms"]["enrichment"]["max"].get<double>(), runs["enrichment_ms_max"][shown].get<double>());
  EXPECT_EQ(scene["machine_probe_ms"].get<double>(), runs["machine_probe_ms"][shown].get<double>());
  EXPECT_EQ(scene["machine_probe_all_threads_ms"].get<double>(),
            runs["machine_probe_all_threads_ms"][shown].get<double>());
  EXPECT_TRUE(runs["identical"].get<bool>());
  std::ifstream markdown(dir / "out.md");
  std::string heading;
  std::getline(markdown, heading);
  EXPECT_NE(heading.find("the fastest of 3 runs"), std::string::npos) << heading;
  // The table of every run: the JSON's figures in order (to 0.1), the shown run's in bold.
  std::string text((std::istreambuf_iterator<char>(markdown)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("| scene | steps/s, run by run | peak step (ms), run by run | steps slower than 33.3 ms, run "
                      "by run |"),
            std::string::npos)
      << text;
  auto listed = [&](const char* key, const char* number_format = "%.1f") {
    std::string list;
    for (std::size_t k = 0; k < 3; ++k) {
      char value[32];
      std::snprintf(value, sizeof value, number_format, runs[key][k].get<double>());
      list += (k ? ", " : "") + (k == shown ? "**" + std::string(value) + "**" : std::string(value));
    }
    return list;
  };
  const std::string row = "| spiral1 | " + listed("steps_per_second") + " | " + listed("peak_step_ms") + " | " +
                          listed("steps_slower_than_target", "%.0f") + " | " + listed("enrichment_ms_max") + " |";
  EXPECT_NE(text.find(row), std::string::npos) << row << "\n" << text;

  const Result zero = run_cli("bench scenes --scenes spiral1 --repeats 0", dir);
  EXPECT_EQ(zero.exit_code, 2);
  EXPECT_NE(zero.stderr_text.find("--repeats: Value 0 not in range 1 to 2147483647"), std::string::npos)
      << zero.stderr_text;
}

TEST(BenchScenes, CountsMatchTheReportOfDgtexRun) {
  const fs::path dir = fresh_dir("counts");
  const fs::path scene = short_spiral(dir, 3);
  const Result run = run_cli("run " + scene.string() + " --out " + (dir / "run").string() + " --no-render --quiet", dir);
  ASSERT_EQ(run.exit_code, 0) << run.stderr_text;
  // --steps 0: the scene's own 3 steps, like `dgtex run`.
  const Result bench = run_cli("bench scenes --scenes " + scene.string() + " --steps 0 --quiet --json " +
                                   (dir / "bench.json").string() + " --markdown " + (dir / "bench.md").string(),
                               dir);
  ASSERT_EQ(bench.exit_code, 0) << bench.stderr_text;
  const nlohmann::json report = read_json(dir / "run" / "report.json");
  const nlohmann::json b = read_json(dir / "bench.json");
  ASSERT_EQ(b["scenes"].size(), 1u);
  EXPECT_EQ(b["scenes"][0]["steps"], 3);
  EXPECT_EQ(b["scenes"][0]["counts"], report["counts"]);
  EXPECT_TRUE(b["scenes"][0]["targets_met"].is_boolean());  // a whole run is judged
  // Each target it missed is named, exactly where its figure falls short, and met means
  // none missed.
  const nlohmann::json& s = b["scenes"][0];
  ASSERT_TRUE(s["targets_missed"].is_array());
  std::set<std::string> missed;
  for (const nlohmann::json& name : s["targets_missed"]) missed.insert(name.get<std::string>());
  EXPECT_EQ(missed.size(), s["targets_missed"].size());
  const auto falls_short = [&](const std::string& name, double value, double target) {
    EXPECT_EQ(missed.count(name), value < target ? 1u : 0u) << name << " = " << value;
    missed.erase(name);
  };
  const bool peak_missed = missed.count("steps_per_second_at_peak") == 1;
  falls_short("steps_per_second", s["steps_per_second"], 30);
  falls_short("steps_per_second_at_peak", s["steps_per_second_at_peak"], 30);
  falls_short("enrichment_ratio", s["ratio_to_table_5_1"]["enrichment"], 20);
  falls_short("assembly_ratio", s["ratio_to_table_5_1"]["assembly"], 20);
  falls_short("solve_ratio", s["ratio_to_table_5_1"]["solve"], 20);
  EXPECT_TRUE(missed.empty()) << "unknown target " << *missed.begin();
  EXPECT_EQ(s["targets_met"].get<bool>(), s["targets_missed"].empty());
  // The Markdown table names them too ("no: " and their labels), or says "yes". (Whichever
  // it is: a test that needed a target missed would fail once the code got fast enough.)
  std::ifstream markdown(dir / "bench.md");
  const std::string text((std::istreambuf_iterator<char>(markdown)), std::istreambuf_iterator<char>());
  const std::size_t verdict = text.find(s["targets_missed"].empty() ? " | yes |" : " | no: ");
  ASSERT_NE(verdict, std::string::npos) << text;
  const std::string verdict_line = text.substr(verdict, text.find('\n', verdict) - verdict);
  const bool assembly_missed = s["ratio_to_table_5_1"]["assembly"].get<double>() < 20;
  EXPECT_EQ(verdict_line.find("assembly") != std::string::npos, assembly_missed) << text;
  // A missed peak step says how many steps were slower than the target; met, none was.
  const int slower = s["steps_slower_than_target"].get<int>();
  EXPECT_EQ(peak_missed, slower > 0);
  const std::string peak_verdict = "peak step (" + std::to_string(slower) + " of 3 steps over 33.3 ms)";
  EXPECT_EQ(text.find(peak_verdict, verdict) != std::string::npos, peak_missed) << peak_verdict << "\n" << text;
  // The solver's totals over the run's three bases (a basis change every step) agree too.
  EXPECT_EQ(report["solver"]["solves"], 3);
  EXPECT_EQ(report["solver"]["pcg_iterations"], b["scenes"][0]["solver"]["pcg_iterations"]);
  EXPECT_EQ(report["solver"]["factorizations"], b["scenes"][0]["solver"]["factorizations"]);
  EXPECT_EQ(report["solver"]["stale_factor_failures"], 0);
  EXPECT_GE(report["counts"]["enrichments"].get<int>(), 1);  // the cut is there after 3 steps
}

TEST(BenchScenes, TimingDoesNotChangeTheSimulationAndStagesFitInTheStep) {
  const Scene scene = load_scene(kScenes + "/spiral1.json");
  SceneRunOptions inline_updates;
  inline_updates.overlap_cut_updates = false;
  const SceneBenchResult r = run_scene_benchmark(scene, "spiral1", 3, {}, inline_updates);
  SceneRun plain(scene, inline_updates);
  for (int s = 0; s < 3; ++s) plain.step();
  EXPECT_EQ(r.displacement, plain.displacement());  // bitwise: same steps, same state
  EXPECT_FALSE(r.overlap_cut_updates);
  // Memory reserved ahead (dgtex/step_memory.h) changes where the arrays lie, not the results.
  SceneRunOptions reserved = inline_updates;
  reserved.reserve_step_memory = true;
  EXPECT_EQ(run_scene_benchmark(scene, "spiral1", 3, {}, reserved).displacement, plain.displacement());
  ASSERT_EQ(r.steps, 3);
  const SceneStepTimes& t = r.times;
  ASSERT_EQ(t.step.size(), 3u);
  ASSERT_EQ(t.enrichment.size(), 3u);
  for (std::size_t s = 0; s < 3; ++s) {
    // The stages run inside the step (step 1 also carries the time-0 cut update on both sides).
    const double stages = t.enrichment[s] + t.projection[s] + t.assembly[s] + t.solve[s];
    EXPECT_LE(stages, t.step[s] + 1e-6) << "step " << s + 1;
    EXPECT_GT(t.assembly[s], 0);
  }
  EXPECT_GT(t.enrichment[0], 0);  // the progressive cut is solved at time 0 and every step
  EXPECT_EQ(r.counts.basis_changes, plain.basis_changes());
  EXPECT_EQ(r.counts.elements, 1);
}

TEST(BenchScenes, OverlappedCutUpdatesGiveTheSameStateAndRunBesideTheStepBefore) {
  // The default (dgtex/scene_run.h): steps 1 and 2 update their cuts themselves (nothing
  // runs beside the first step); from step 3 on, a step's update ran beside the step
  // before, so it is counted in the step that uses it and fits in the one before.
  const Scene scene = load_scene(kScenes + "/spiral1.json");
  const SceneBenchResult r = run_scene_benchmark(scene, "spiral1", 4);
  SceneRunOptions inline_updates;
  inline_updates.overlap_cut_updates = false;
  SceneRun plain(scene, inline_updates);
  for (int s = 0; s < 4; ++s) plain.step();
  EXPECT_EQ(r.displacement, plain.displacement());  // bitwise
  EXPECT_EQ(r.counts.basis_changes, plain.basis_changes());
  EXPECT_TRUE(r.overlap_cut_updates);
  const SceneStepTimes& t = r.times;
  ASSERT_EQ(t.step.size(), 4u);
  for (std::size_t s = 0; s < 4; ++s) {
    const double own = t.projection[s] + t.assembly[s] + t.solve[s];
    EXPECT_GT(t.enrichment[s], 0) << "step " << s + 1;
    if (s < 2 || omp_get_max_threads() < 2) {
      EXPECT_LE(t.enrichment[s] + own, t.step[s] + 1e-6) << "step " << s + 1;
    } else {
      EXPECT_LE(own, t.step[s] + 1e-6) << "step " << s + 1;
      EXPECT_LE(t.enrichment[s], t.step[s - 1] + 1e-6) << "step " << s + 1;
    }
    // The update beside steps 2-4 had its own team: one thread at least, one fewer than all.
    const int threads = omp_get_max_threads();
    if (s == 0 || threads < 2) {
      EXPECT_EQ(t.cut_update_threads[s], 0) << "step " << s + 1;
    } else {
      EXPECT_GE(t.cut_update_threads[s], 1) << "step " << s + 1;
      EXPECT_LE(t.cut_update_threads[s], threads - 1) << "step " << s + 1;
    }
  }
}

TEST(BenchScenes, ThesisTableRowsAreThoseOfTable51) {
  const ThesisTable51Row* spiral6 = thesis_table_5_1_row("spiral6");
  ASSERT_NE(spiral6, nullptr);
  EXPECT_EQ(spiral6->enrichments, 6);
  EXPECT_EQ(spiral6->enrichment_ms, 1701);
  EXPECT_EQ(spiral6->assembly_ms, 38);
  EXPECT_EQ(spiral6->solve_ms, 0.7);
  const ThesisTable51Row* bunny = thesis_table_5_1_row("fracture");
  ASSERT_NE(bunny, nullptr);
  EXPECT_EQ(bunny->elements, 552);
  EXPECT_EQ(bunny->solve_ms, 917);
  EXPECT_EQ(thesis_table_5_1_row("cylinder_buckling"), nullptr);
  EXPECT_EQ(bench_scene_names().size(), 7u);
  for (const std::string& name : bench_scene_names()) EXPECT_TRUE(fs::exists(kScenes + "/" + name + ".json")) << name;
}

TEST(BenchScenes, BadInputExitsWithTwoAndNamesTheProblem) {
  const fs::path dir = fresh_dir("bad");
  const Result unknown = run_cli("bench scenes --scene-dir " + kScenes + " --scenes no_such_scene --quiet", dir);
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_NE(unknown.stderr_text.find("no_such_scene"), std::string::npos) << unknown.stderr_text;
  const Result static_scene =
      run_cli("bench scenes --scenes " + kScenes + "/clamped_plate.json --steps 1 --quiet", dir);
  EXPECT_EQ(static_scene.exit_code, 2);
  EXPECT_NE(static_scene.stderr_text.find("static"), std::string::npos) << static_scene.stderr_text;
  EXPECT_THROW(run_scene_benchmark(load_scene(kScenes + "/spiral1.json"), "spiral1", -1), std::invalid_argument);
  // Output paths that cannot be written are refused before the first scene runs, not
  // after minutes of work; a negative step count names the integers --steps takes.
  const Result json_folder = run_cli(
      "bench scenes --scene-dir " + kScenes + " --scenes spiral1 --steps 1 --json " + (dir / "no" / "r.json").string(),
      dir);
  EXPECT_EQ(json_folder.exit_code, 2);
  EXPECT_NE(json_folder.stderr_text.find("--json: folder '" + (dir / "no").string() + "' does not exist"),
            std::string::npos)
      << json_folder.stderr_text;
  EXPECT_EQ(json_folder.stderr_text.find("spiral1"), std::string::npos) << json_folder.stderr_text;
  const Result markdown_folder = run_cli("bench scenes --scene-dir " + kScenes + " --markdown " + dir.string(), dir);
  EXPECT_EQ(markdown_folder.exit_code, 2);
  EXPECT_NE(markdown_folder.stderr_text.find("is a folder; give a file name"), std::string::npos)
      << markdown_folder.stderr_text;
  const Result steps = run_cli("bench scenes --steps -1", dir);
  EXPECT_EQ(steps.exit_code, 2);
  EXPECT_NE(steps.stderr_text.find("--steps: Value -1 not in range 0 to 2147483647"), std::string::npos)
      << steps.stderr_text;
  const Result team = run_cli("bench scenes --cut-update-threads -2", dir);
  EXPECT_EQ(team.exit_code, 2);
  EXPECT_NE(team.stderr_text.find("--cut-update-threads: Value -2 not in range 0 to 2147483647"), std::string::npos)
      << team.stderr_text;
}
