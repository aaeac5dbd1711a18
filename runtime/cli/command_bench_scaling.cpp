// dgtex bench scaling: time of each kernel family of the shell step (enrichment solve,
// assembly, polar decomposition, factorization) and of whole scene steps at several
// OpenMP thread counts, and scenes per second of many independent scenes at once (one
// thread each) against one scene using all threads (dgtex/scaling_benchmark.h).
#include <CLI/CLI.hpp>
#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "commands.h"
#include "count_option.h"
#include "example_scenes.h"
#include "gnuplot_chart.h"
#include "dgtex/benchmark_machine.h"
#include "dgtex/mesh_error.h"
#include "dgtex/model_error.h"
#include "dgtex/scaling_benchmark.h"
#include "dgtex/scene_io.h"
#include "dgtex/version.h"
#include "option_errors.h"
#include "output_paths.h"

namespace dgtex::cli {
namespace {

const std::vector<std::string> kFamilies = {"enrichment_solve", "assembly", "polar_decomposition", "factorization",
                                            "scene_step", "batch"};

std::string stem(const std::string& path) { return std::filesystem::path(path).stem().string(); }

std::string format(const char* fmt, double a) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, fmt, a);
  return buffer;
}

nlohmann::json kernel_json(const KernelScaling& k) {
  nlohmann::json cases = nlohmann::json::array();
  for (std::size_t i = 0; i < k.threads.size(); ++i)
    cases.push_back({{"threads", k.threads[i]}, {"ms", k.ms[i]}, {"speedup", k.ms[i] > 0 ? k.ms[0] / k.ms[i] : 0.0}});
  return {{"family", k.family}, {"workload", k.workload}, {"cases", cases},
          {"identical_across_threads", k.identical_across_threads}};
}

nlohmann::json batch_json(const BatchThroughput& b) {
  return {{"scene", b.scene},
          {"runs", b.runs},
          {"steps", b.steps},
          {"solo_threads", b.solo_threads},
          {"solo_ms", b.solo_ms},
          {"batch_ms", b.batch_ms},
          {"solo_scenes_per_second", b.solo_scenes_per_second()},
          {"batch_scenes_per_second", b.batch_scenes_per_second()},
          {"batch_over_solo", b.solo_ms > 0 && b.batch_ms > 0 ? b.solo_ms / b.batch_ms : 0.0},
          {"identical", b.identical},
          {"max_relative_difference", b.max_relative_difference}};
}

std::string markdown_tables(const std::vector<int>& threads, const std::vector<KernelScaling>& kernels,
                            const std::vector<BatchThroughput>& batches) {
  std::ostringstream out;
  if (!kernels.empty()) {
    out << "| family | workload |";
    for (int t : threads) out << " " << t << (t == 1 ? " thread" : " threads") << " ms |";
    for (std::size_t i = 1; i < threads.size(); ++i) out << " speed-up " << threads[0] << "->" << threads[i] << " |";
    out << " identical |\n|---|---|";
    for (std::size_t i = 0; i < 2 * threads.size() - 1; ++i) out << "---:|";
    out << "---|\n";
    for (const KernelScaling& k : kernels) {
      out << "| " << k.family << " | " << k.workload << " |";
      for (double ms : k.ms) out << " " << format("%.3g", ms) << " |";
      for (std::size_t i = 1; i < k.ms.size(); ++i) out << " " << format("%.2f", k.ms[0] / k.ms[i]) << "x |";
      out << " " << (k.identical_across_threads ? "yes" : "NO") << " |\n";
    }
  }
  if (!batches.empty()) {
    if (!kernels.empty()) out << "\n";
    out << "| scene | runs x steps | solo: one after another, all threads (scenes/s) "
           "| batch: all at once, 1 thread each (scenes/s) | batch / solo | identical (max rel. difference) |\n"
        << "|---|---|---:|---:|---:|---|\n";
    for (const BatchThroughput& b : batches)
      out << "| " << stem(b.scene) << " | " << b.runs << " x " << b.steps << " | " << format("%.3g", b.solo_scenes_per_second())
          << " (" << b.solo_threads << " threads) | " << format("%.3g", b.batch_scenes_per_second()) << " | "
          << format("%.2f", b.solo_ms / b.batch_ms) << "x | "
          << (b.identical ? std::string("yes") : "NO (" + format("%.1e", b.max_relative_difference) + ")") << " |\n";
  }
  return out.str();
}

// Left: speed-up over the first thread count per family (and the ideal); right: scenes
// per second, solo against batch. `about` (machine, command) heads the chart.
std::string write_chart(const std::string& path, const std::vector<KernelScaling>& kernels,
                        const std::vector<BatchThroughput>& batches, const std::string& about) {
  std::ostringstream data;
  for (const KernelScaling& k : kernels) {
    data << "# " << k.family << "\n";
    for (std::size_t i = 0; i < k.threads.size(); ++i) data << k.threads[i] << " " << k.ms[0] / k.ms[i] << "\n";
    data << "\n\n";
  }
  data << "# batch\n";
  for (const BatchThroughput& b : batches)
    data << "\"" << stem(b.scene) << "\" " << b.solo_scenes_per_second() << " " << b.batch_scenes_per_second() << "\n";
  data << "\n\n";
  const bool two = !kernels.empty() && !batches.empty();
  return draw_gnuplot_chart(path, two ? 1200 : 700, 500, data.str(), [&](const std::string& file) {
    std::ostringstream s;
    s << "set termoption noenhanced\n";  // names with underscores stay as they are
    s << "set multiplot layout 1," << (two ? 2 : 1) << " title " << gnuplot_quoted(about) << " font ',10'\n";
    if (!kernels.empty()) {
      int max_threads = 1;
      for (const KernelScaling& k : kernels) max_threads = std::max(max_threads, k.threads.back());
      s << "set title 'speed-up over " << kernels.front().threads.front() << " thread(s)'\nset xlabel 'OpenMP threads'\n"
        << "set ylabel 'speed-up'\nset key top left font ',9'\nset grid\nset yrange [0:*]\nset xrange [0.8:" << max_threads + 0.2 << "]\n"
        << "set xtics 1\nplot x with lines dashtype 2 lc rgb 'gray' title 'ideal'";
      for (std::size_t k = 0; k < kernels.size(); ++k) {
        // "family (scene)" where the workload names a scene file.
        const std::size_t colon = kernels[k].workload.find(':');
        const std::string label =
            kernels[k].family + (colon == std::string::npos ? "" : " (" + stem(kernels[k].workload.substr(0, colon)) + ")");
        s << ", '" << file << "' index " << k << " using 1:2 with linespoints lw 2 title '" << label << "'";
      }
      s << "\n";
    }
    if (!batches.empty()) {
      s << "reset\nset termoption noenhanced\nset title 'independent scenes: scenes per second'\nset style data histograms\n"
        << "set style histogram clustered gap 1\nset style fill solid 0.8 border -1\nset ylabel 'scenes/s'\n"
        << "set logscale y\nset grid ytics\nset key top right\n"
        << "plot '" << file << "' index " << kernels.size() << " using 2:xtic(1) title 'solo, " << batches.front().solo_threads
        << " threads each', '' index " << kernels.size() << " using 3 title 'batch, " << batches.front().runs
        << " at once, 1 thread each'\n";
    }
    s << "unset multiplot\n";
    return s.str();
  });
}

}  // namespace

int bench_scaling_command(int argc, char** argv) {
  CLI::App app{"Thread scaling of the kernel families of a shell step (enrichment solve, assembly, polar decomposition, "
               "factorization) and of whole scene steps; scenes per second of independent scenes run at once (one "
               "thread each) against one after another (all threads each)",
               "dgtex bench scaling"};
  std::vector<int> threads;
  for (int t = 1; t <= omp_get_num_procs(); ++t) threads.push_back(t);
  std::string scene_path = example_scene("cylinder_buckling.json"), cut_scene_path = example_scene("chad.json");
  std::vector<std::string> families = kFamilies, batch_scenes;
  std::string json_path, chart_path, markdown_path;
  // 20 scene steps: over 5 (steps 2-6, its second step's cut update inline), chad's speed-up
  // read 0.99-1.11x at 2 threads (sessions 13, 23 and 67), over 20 1.09-1.56x (session 67).
  int repeats = 3, steps = 20, batch_runs = 0, batch_steps = 5;
  std::int64_t polar_count = 1 << 20;
  app.add_option("--threads-list", threads, "OpenMP thread counts (default: 1 to the number of cores)")
      ->delimiter(',')
      ->capture_default_str()
      ->check(thread_count());
  // Scene files are read only where a chosen family needs them: a missing one given for
  // another family passed without a word.
  app.add_option("--scene", scene_path, "plain dynamic scene: assembly, factorization, scene steps")
      ->capture_default_str()
      ->check(CLI::ExistingFile);
  app.add_option("--cut-scene", cut_scene_path, "scene with cuts: enrichment solve, enriched assembly, scene steps")
      ->capture_default_str()
      ->check(CLI::ExistingFile);
  app.add_option("--families", families,
                 "what to time: enrichment_solve, assembly, polar_decomposition, factorization, scene_step, batch")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--repeats", repeats, "kernel timings: best of this many runs")
      ->capture_default_str()
      ->check(at_least_one());
  app.add_option("--steps", steps, "scene_step: timed steps per thread count")
      ->capture_default_str()
      ->check(at_least_one());
  app.add_option("--polar-count", polar_count, "polar_decomposition: matrices per batch")
      ->capture_default_str()
      ->check(at_least_one());
  app.add_option("--batch-scenes", batch_scenes, "batch: scene files (default: --cut-scene and --scene)")
      ->delimiter(',')
      ->check(CLI::ExistingFile);
  app.add_option("--batch-runs", batch_runs, "batch: independent runs K (default: the largest thread count)")
      ->check(at_least_one());
  app.add_option("--batch-steps", batch_steps, "batch: steps per run")->capture_default_str()->check(at_least_one());
  app.add_option("--json", json_path, "write the results as JSON")->check(writable_file());
  app.add_option("--markdown", markdown_path, "write the Markdown tables to FILE too")->check(writable_file());
  app.add_option("--chart", chart_path, "chart with gnuplot (PNG if FILE ends in .png, else SVG)")
      ->check(writable_file());
  try {
    app.parse(argc, argv);
    check_list_items(app, argc, argv);
  } catch (const CLI::ParseError& e) {
    return exit_on_option_error(app, e);
  }
  std::vector<InputFile> inputs = {{"the scene of --scene", scene_path}, {"the scene of --cut-scene", cut_scene_path}};
  for (const std::string& path : batch_scenes) inputs.push_back({"a scene of --batch-scenes", path});
  if (!outputs_are_distinct(app, {{"--json", &json_path}, {"--markdown", &markdown_path}, {"--chart", &chart_path}},
                            inputs))
    return 2;
  if (!thread_counts_increase(app, threads)) return 2;
  for (const std::string& f : families)
    if (std::find(kFamilies.begin(), kFamilies.end(), f) == kFamilies.end()) {
      std::fprintf(stderr, "dgtex bench scaling: --families: unknown family '%s'; valid: enrichment_solve, assembly, "
                           "polar_decomposition, factorization, scene_step, batch\n", f.c_str());
      return 2;
    }
  const std::set<std::string> chosen(families.begin(), families.end());
  // F, R and the first thread count's R: 27 doubles a matrix.
  const std::optional<std::int64_t> available = memory_for_options(app);
  if (!available) return 2;
  if (const std::int64_t most =
          chosen.count("polar_decomposition") ? most_that_fit(polar_count, 27 * 8, *available) : -1;
      most >= 0) {
    std::fprintf(stderr,
                 "dgtex bench scaling: --polar-count: %lld matrices (216 bytes each) would not fit the %s of memory "
                 "available; expected at most %lld (see dgtex bench scaling --help)\n",
                 static_cast<long long>(polar_count), memory_size_text(*available).c_str(),
                 static_cast<long long>(most));
    return 2;
  }
  // The chart's heading: the machine (before any run changes the thread count) and command.
  const std::string about = describe_machine_and_probe() + ", OMP_WAIT_POLICY=" + omp_wait_policy_name() + "\n" +
                            bench_command_line(argc, argv);
  if (batch_scenes.empty()) batch_scenes = {cut_scene_path, scene_path};
  const int max_threads = *std::max_element(threads.begin(), threads.end());
  if (batch_runs == 0) batch_runs = max_threads;

  std::vector<KernelScaling> kernels;
  std::vector<BatchThroughput> batches;
  std::string current = scene_path;  // for error messages
  try {
    // Scenes are read only when a chosen family needs them.
    const bool need_scene = chosen.count("assembly") || chosen.count("factorization") || chosen.count("scene_step");
    const bool need_cut_scene = chosen.count("enrichment_solve") || chosen.count("assembly") || chosen.count("scene_step");
    Scene scene, cut_scene;
    std::vector<Scene> batch;
    current = scene_path;
    if (need_scene) scene = load_scene(scene_path);
    current = cut_scene_path;
    if (need_cut_scene) cut_scene = load_scene(cut_scene_path);
    if (chosen.count("batch"))
      for (const std::string& path : batch_scenes) {
        current = path;
        batch.push_back(load_scene(path));
      }
    // A scene a chosen family cannot use is refused before any family runs (they take minutes).
    try {
      if (chosen.count("enrichment_solve")) check_scaling_scene(cut_scene, "enrichment_solve");
      if (chosen.count("assembly")) check_scaling_scene(cut_scene, "enriched_assembly");
      if (chosen.count("factorization")) check_scaling_scene(scene, "factorization");
      if (chosen.count("scene_step"))
        for (const Scene* s : {&cut_scene, &scene}) check_scaling_scene(*s, "scene_step");
      for (const Scene& s : batch) check_scaling_scene(s, "batch");
    } catch (const std::invalid_argument& e) {  // the message names the scene
      std::fprintf(stderr, "dgtex bench scaling: %s\n", e.what());
      return 2;
    }
    auto note = [](const std::string& what) { std::fprintf(stderr, "bench scaling: %s ...\n", what.c_str()); };
    if (chosen.count("enrichment_solve")) {
      note("enrichment solve, " + cut_scene_path);
      current = cut_scene_path;
      kernels.push_back(scale_enrichment_solve(cut_scene, threads, repeats));
    }
    if (chosen.count("assembly")) {
      note("assembly, " + scene_path);
      current = scene_path;
      kernels.push_back(scale_assembly(scene, false, threads, repeats));
      note("enriched assembly, " + cut_scene_path);
      current = cut_scene_path;
      kernels.push_back(scale_assembly(cut_scene, true, threads, repeats));
    }
    if (chosen.count("polar_decomposition")) {
      note("polar decomposition");
      current = "polar decomposition of " + std::to_string(polar_count) + " matrices";  // no scene
      kernels.push_back(scale_polar_decomposition(polar_count, threads, repeats));
    }
    if (chosen.count("factorization")) {
      note("factorization, " + scene_path);
      current = scene_path;
      kernels.push_back(scale_factorization(scene, threads, repeats));
    }
    if (chosen.count("scene_step")) {
      for (const Scene* s : {&cut_scene, &scene}) {
        current = s->source_name;
        note("scene steps, " + current);
        kernels.push_back(scale_scene_steps(*s, steps, threads));
      }
    }
    for (const Scene& s : batch) {
      current = s.source_name;
      note("batch throughput, " + current);
      batches.push_back(measure_batch_throughput(s, batch_runs, batch_steps, max_threads));
    }
  } catch (const SceneError& e) {
    std::fprintf(stderr, "dgtex bench scaling: %s\n", e.what());
    return 2;
  } catch (const MeshError& e) {
    std::fprintf(stderr, "dgtex bench scaling: %s: mesh: %s\n", current.c_str(), e.what());
    return 2;
  } catch (const ModelError& e) {
    std::fprintf(stderr, "dgtex bench scaling: %s: %s\n", current.c_str(), e.what());
    return 1;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "dgtex bench scaling: %s: %s\n", current.c_str(), e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dgtex bench scaling: %s: %s\n", current.c_str(), e.what());
    return 1;
  }

  const std::string tables = markdown_tables(threads, kernels, batches);
  std::printf("dgtex bench scaling: %d cores, OMP_WAIT_POLICY=%s (kernels: best of %d, ms)\n\n%s", omp_get_num_procs(),
              omp_wait_policy_name().c_str(), repeats, tables.c_str());
  try {
    if (!markdown_path.empty()) write_output_file(markdown_path, tables, "--markdown");
    if (!json_path.empty()) {
      nlohmann::json j = {{"dgtex_version", version()},
                          {"cores", omp_get_num_procs()},
                          {"threads", threads},
                          {"repeats", repeats},
                          {"omp_wait_policy", omp_wait_policy_name()},
                          {"kernels", nlohmann::json::array()},
                          {"batch", nlohmann::json::array()}};
      for (const KernelScaling& k : kernels) j["kernels"].push_back(kernel_json(k));
      for (const BatchThroughput& b : batches) j["batch"].push_back(batch_json(b));
      write_output_file(json_path, j.dump(2) + "\n", "--json");
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dgtex bench scaling: %s\n", e.what());
    return 1;
  }
  if (const std::string failure = chart_path.empty() ? "" : write_chart(chart_path, kernels, batches, about);
      !failure.empty()) {
    std::fprintf(stderr, "dgtex bench scaling: no chart '%s': %s\n", chart_path.c_str(), failure.c_str());
    return 1;
  }
  return 0;
}

}  // namespace dgtex::cli
