// dgtex bench accuracy: speed against accuracy (dgtex/accuracy_benchmark.h). Writes, into
// --out DIR, one chart per sweep (accuracy_<name>.png or .svg: error against ms, log-log,
// one line per series, machine and command in the title), accuracy.json and accuracy.md.
#include <CLI/CLI.hpp>

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "commands.h"
#include "count_option.h"
#include "example_scenes.h"
#include "dgtex/accuracy_benchmark.h"
#include "dgtex/benchmark_machine.h"
#include "dgtex/scene_io.h"
#include "gnuplot_chart.h"
#include "option_errors.h"
#include "output_paths.h"

namespace dgtex::cli {
namespace {

// Error against time per series; reference points (error 0) become dashed vertical lines.
std::string write_chart(const std::string& path, const AccuracyChart& chart, const std::string& machine,
                        const std::string& command) {
  const std::vector<std::string> series = chart.series();
  std::ostringstream data;
  for (const std::string& s : series) {
    data << "# " << s << "\n";
    for (const AccuracyPoint& p : chart.points)
      if (p.series == s && p.error > 0) data << std::max(p.ms, 1e-3) << " " << p.error << " " << gnuplot_quoted(p.label) << "\n";
    data << "\n\n";
  }
  return draw_gnuplot_chart(path, 960, 640, data.str(), [&](const std::string& data_file) {
    std::ostringstream g;
    g << "set title " << gnuplot_quoted(chart.title + "\n" + machine + "\n" + command) << " noenhanced font ',10'\n"
      << "set logscale xy\nset xlabel " << gnuplot_quoted(chart.time_label) << " noenhanced\n"
      << "set ylabel " << gnuplot_quoted(chart.error_label) << " noenhanced font ',9'\n"
      << "set format y '10^{%L}'\nset grid\nset key outside bottom center horizontal noenhanced\n"
      << "set offsets graph 0.05, graph 0.12, graph 0.1, graph 0.1\n";
    int arrow = 0;
    for (std::size_t k = 0; k < series.size(); ++k)
      for (const AccuracyPoint& p : chart.points)
        if (p.series == series[k] && p.error == 0) {
          ++arrow;
          g << "set arrow " << arrow << " from " << std::max(p.ms, 1e-3) << ", graph 0 to " << std::max(p.ms, 1e-3)
            << ", graph 1 nohead dt 2 lt " << k + 1 << "\n"
            << "set label " << arrow << " " << gnuplot_quoted("reference: " + p.label + " (" + series[k] + ")")
            << " at " << std::max(p.ms, 1e-3) << ", graph 0.03 rotate by 90 left offset -0.7, 0 noenhanced font ',8' tc lt "
            << k + 1 << "\n";
        }
    const auto drawn = [&](const std::string& name) {
      return std::any_of(chart.points.begin(), chart.points.end(),
                         [&](const AccuracyPoint& p) { return p.series == name && p.error > 0; });
    };
    if (std::none_of(series.begin(), series.end(), drawn)) {
      // Every run equals its reference, and error 0 has no place on a log scale: with fixed
      // ranges gnuplot draws the axes and the references instead of failing to scale them.
      double low = 1e300, high = 0;
      for (const AccuracyPoint& p : chart.points) {
        low = std::min(low, std::max(p.ms, 1e-3));
        high = std::max(high, p.ms);
      }
      if (!(high > low)) low = 1e-3, high = std::max(1.0, 2 * high);
      g << "set xrange [" << low / 2 << ":" << high * 2 << "]\nset yrange [1e-16:1]\n"
        << "set label " << arrow + 1 << " 'every error is 0: the runs equal their references' at graph 0.5, graph 0.5"
        << " center\nplot 1/0 notitle";
      return g.str();
    }
    g << "plot ";
    bool first = true;
    for (std::size_t k = 0; k < series.size(); ++k) {
      if (!drawn(series[k])) continue;
      g << (first ? "" : ", ") << "'" << data_file << "' index " << k << " using 1:2 with linespoints lt " << k + 1
        << " pt 7 title " << gnuplot_quoted(series[k]) << ", '' index " << k
        << " using 1:2:3 with labels offset 0.6, 0.6 left font ',8' noenhanced notitle";
      first = false;
    }
    return g.str();
  });
}

const std::vector<std::string> kChartNames = {"plate", "quadrature", "texture", "tolerance", "rotation",
                                              "scene_quadrature"};

std::vector<std::string> split_names(const std::vector<std::string>& names) {
  for (const std::string& n : names)
    if (std::find(kChartNames.begin(), kChartNames.end(), n) == kChartNames.end())
      throw std::invalid_argument("--charts: unknown chart '" + n +
                                  "'; valid: plate, quadrature, texture, tolerance, rotation, scene_quadrature");
  return names;
}

}  // namespace

int bench_accuracy_command(int argc, char** argv) {
  CLI::App app{"Speed against accuracy: error against time for mesh refinement, enriched quadrature, texture "
               "resolution, solver tolerance, rotation clusters and a scene's quadrature tolerance",
               "dgtex bench accuracy"};
  std::vector<std::string> charts = {"plate", "quadrature", "texture", "tolerance", "rotation", "scene_quadrature"};
  std::string out_dir = "accuracy", format = "png", clock = "cpu";
  int threads = 1, repeat = 3;
  PlateAccuracyOptions plate;
  QuadratureAccuracyOptions quadrature;
  TextureAccuracyOptions texture;
  ToleranceAccuracyOptions tolerance;
  RotationAccuracyOptions rotation;
  SceneQuadratureAccuracyOptions scene_quadrature;
  tolerance.shell_scene = example_scene("cylinder_buckling.json");
  rotation.scene = example_scene("accordion.json");
  scene_quadrature.scene = example_scene("slinky.json");
  // The sweeps' defaults, to check the options one at a time against (below).
  const PlateAccuracyOptions plate_defaults = plate;
  const QuadratureAccuracyOptions quadrature_defaults = quadrature;
  const ToleranceAccuracyOptions tolerance_defaults = tolerance;
  const RotationAccuracyOptions rotation_defaults = rotation;
  const SceneQuadratureAccuracyOptions scene_quadrature_defaults = scene_quadrature;
  app.add_option("--charts", charts, "plate, quadrature, texture, tolerance, rotation, scene_quadrature")
      ->delimiter(',')
      ->capture_default_str();
  app.add_option("--out", out_dir, "output folder (charts, accuracy.json, accuracy.md)")
      ->capture_default_str()
      ->check(creatable_folder());
  app.add_option("--format", format, "chart format: png or svg")->capture_default_str()->check(CLI::IsMember({"png", "svg"}));
  app.add_option("--clock", clock, "cpu (process CPU time; robust on a shared machine with 1 thread) or wall")
      ->capture_default_str()->check(CLI::IsMember({"cpu", "wall"}));
  app.add_option("--threads", threads, "OpenMP threads for every sweep")->capture_default_str()->check(thread_count());
  app.add_option("--repeat", repeat, "runs per cheap case; the best time counts")
      ->capture_default_str()
      ->check(at_least_one());
  app.add_option("--plate-divisions", plate.divisions, "plate meshes n x n (even n)")
      ->delimiter(',')
      ->capture_default_str()
      ->check(whole_int());
  app.add_option("--quadrature-resolution", quadrature.resolution, "texels per element side T of the quadrature sweep")
      ->capture_default_str()
      ->check(whole_int());
  app.add_option("--quadrature-tolerances", quadrature.tolerances, "merge tolerances (the per-texel rule always runs)")
      ->delimiter(',')->capture_default_str();
  app.add_option("--quadrature-elements", quadrature.elements, "quad8, tri6")->delimiter(',')->capture_default_str();
  app.add_option("--texture-sizes", texture.resolutions, "texture resolutions T")
      ->delimiter(',')
      ->capture_default_str()
      ->check(whole_int());
  app.add_option("--shell-scene", tolerance.shell_scene, "dynamic corotated scene of the shell PCG tolerance sweep")
      ->capture_default_str()
      ->check(CLI::ExistingFile);
  app.add_option("--shell-steps", tolerance.shell_steps, "steps per shell run")->capture_default_str()->check(whole_int());
  app.add_option("--shell-tolerances", tolerance.shell_tolerances, "PCG relative tolerances")->delimiter(',')
      ->capture_default_str();
  app.add_option("--multigrid-size", tolerance.multigrid_resolution, "T of the multigrid tolerance sweep (slit domain)")
      ->capture_default_str()
      ->check(whole_int());
  app.add_option("--multigrid-tolerances", tolerance.multigrid_tolerances, "multigrid relative tolerances")
      ->delimiter(',')->capture_default_str();
  app.add_option("--rotation-scene", rotation.scene, "dynamic corotated scene with cuts of the rotation sweep")
      ->capture_default_str()
      ->check(CLI::ExistingFile);
  app.add_option("--rotation-steps", rotation.steps, "steps per rotation run")->capture_default_str()->check(whole_int());
  app.add_option("--rotation-blocks", rotation.block_texels, "rotation cluster blocks B (texels; per point is the reference)")
      ->delimiter(',')
      ->capture_default_str()
      ->check(whole_int());
  app.add_option("--scene-quadrature-scene", scene_quadrature.scene,
                 "dynamic scene with cuts of the scene quadrature sweep")
      ->capture_default_str()
      ->check(CLI::ExistingFile);
  app.add_option("--scene-quadrature-steps", scene_quadrature.steps,
                 "steps per run of that sweep (0: the scene's own analysis.steps)")
      ->capture_default_str()
      ->check(whole_int());
  app.add_option("--scene-quadrature-tolerances", scene_quadrature.tolerances, "merge tolerances of that sweep")
      ->delimiter(',')->capture_default_str();
  app.add_option("--scene-quadrature-reference", scene_quadrature.reference_tolerance,
                 "the tight merge tolerance the sweep's errors are measured against")->capture_default_str();
  app.add_flag("!--no-time-step-error", scene_quadrature.time_step_error,
               "scene quadrature chart without the run at half the time step");
  app.add_flag("!--no-shell", tolerance.shell, "tolerance chart without the shell PCG series");
  app.add_flag("!--no-multigrid", tolerance.multigrid, "tolerance chart without the multigrid series");
  try {
    app.parse(argc, argv);
    check_list_items(app, argc, argv);
  } catch (const CLI::ParseError& e) {
    return exit_on_option_error(app, e);
  }
  const std::string command = bench_command_line(argc, argv);
  try {
    plate.repeat = quadrature.repeat = texture.repeat = tolerance.repeat = repeat;
    const AccuracyClock which = clock == "cpu" ? AccuracyClock::cpu : AccuracyClock::wall;
    plate.clock = quadrature.clock = texture.clock = tolerance.clock = rotation.clock = scene_quadrature.clock = which;
    omp_set_num_threads(threads);
    // Every sweep's options before the first sweep runs: a bad value of the last sweep
    // ended the command minutes in, and those of a sweep not chosen were ignored without a
    // word (their defaults are valid). The library names the sweep's field in words, so
    // each option is first checked alone on the sweep's defaults, and a bad one is named
    // (`--plate-divisions: plate divisions: n = 3; ...`); then the sweeps as given (options
    // that are valid alone but not together).
    try {
      split_names(charts);
      auto alone = [](const char* option, const std::function<void()>& check) {
        try {
          check();
        } catch (const std::invalid_argument& e) {
          throw std::invalid_argument(std::string(option) + ": " + e.what());
        }
      };
      auto with = [](auto defaults, auto set, auto check) {
        set(defaults);
        return [=] { check(defaults); };
      };
      alone("--plate-divisions", [&] { check_plate_accuracy_options(plate); });
      alone("--quadrature-resolution", with(quadrature_defaults, [&](auto& o) { o.resolution = quadrature.resolution; },
                                            check_quadrature_accuracy_options));
      alone("--quadrature-tolerances", with(quadrature_defaults, [&](auto& o) { o.tolerances = quadrature.tolerances; },
                                            check_quadrature_accuracy_options));
      alone("--quadrature-elements", with(quadrature_defaults, [&](auto& o) { o.elements = quadrature.elements; },
                                          check_quadrature_accuracy_options));
      alone("--texture-sizes", [&] { check_texture_accuracy_options(texture); });
      alone("--shell-steps", with(tolerance_defaults, [&](auto& o) { o.shell_steps = tolerance.shell_steps; },
                                  check_tolerance_accuracy_options));
      alone("--shell-tolerances", with(tolerance_defaults, [&](auto& o) { o.shell_tolerances = tolerance.shell_tolerances; },
                                       check_tolerance_accuracy_options));
      alone("--multigrid-size", with(tolerance_defaults, [&](auto& o) { o.multigrid_resolution = tolerance.multigrid_resolution; },
                                     check_tolerance_accuracy_options));
      alone("--shell-scene", with(tolerance_defaults, [&](auto& o) { o.shell_scene = tolerance.shell_scene; },
                                  check_tolerance_accuracy_options));
      alone("--multigrid-tolerances",
            with(tolerance_defaults, [&](auto& o) { o.multigrid_tolerances = tolerance.multigrid_tolerances; },
                 check_tolerance_accuracy_options));
      alone("--rotation-steps", with(rotation_defaults, [&](auto& o) { o.steps = rotation.steps; },
                                     check_rotation_accuracy_options));
      alone("--rotation-blocks", with(rotation_defaults, [&](auto& o) { o.block_texels = rotation.block_texels; },
                                      check_rotation_accuracy_options));
      alone("--rotation-scene", with(rotation_defaults, [&](auto& o) { o.scene = rotation.scene; },
                                     check_rotation_accuracy_options));
      alone("--scene-quadrature-steps", with(scene_quadrature_defaults, [&](auto& o) { o.steps = scene_quadrature.steps; },
                                             check_scene_quadrature_accuracy_options));
      alone("--scene-quadrature-scene", with(scene_quadrature_defaults, [&](auto& o) { o.scene = scene_quadrature.scene; },
                                             check_scene_quadrature_accuracy_options));
      check_plate_accuracy_options(plate);
      check_quadrature_accuracy_options(quadrature);
      check_texture_accuracy_options(texture);
      check_tolerance_accuracy_options(tolerance);
      check_rotation_accuracy_options(rotation);
      check_scene_quadrature_accuracy_options(scene_quadrature);
    } catch (const std::invalid_argument& e) {
      std::fprintf(stderr, "dgtex bench accuracy: %s (see dgtex bench accuracy --help)\n", e.what());
      return 2;
    } catch (const SceneError& e) {  // a scene option's file (its path, field and value)
      std::fprintf(stderr, "dgtex bench accuracy: %s\n", e.what());
      return 2;
    }
    // An earlier run's charts and tables in --out go first (a chart of a sweep not run now
    // stayed beside a JSON without its data), never a scene the sweeps read.
    std::vector<std::string> outputs = {"accuracy.json", "accuracy.md"};
    for (const std::string& name : kChartNames)
      for (const char* extension : {".png", ".svg"}) outputs.push_back("accuracy_" + name + extension);
    check_outputs_spare_inputs(out_dir, outputs,
                               {{"the scene of --shell-scene", tolerance.shell_scene},
                                {"the scene of --rotation-scene", rotation.scene},
                                {"the scene of --scene-quadrature-scene", scene_quadrature.scene}});
    create_output_folder(out_dir, "--out");
    if (const int removed = remove_earlier_outputs(out_dir, outputs); removed > 0)
      std::fprintf(stderr, "dgtex bench accuracy: removed %d files of an earlier run from %s\n", removed, out_dir.c_str());
    const std::string machine = describe_machine_and_probe();
    const auto start = std::chrono::steady_clock::now();
    const AccuracyProgress progress = [&](const std::string& line) {
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::fprintf(stderr, "[%6.1f s] %s\n", s, line.c_str());
      std::fflush(stderr);
    };
    std::fprintf(stderr, "dgtex bench accuracy on %s\n", machine.c_str());
    std::vector<AccuracyChart> results;
    for (const std::string& name : charts) {
      if (name == "plate") results.push_back(run_plate_accuracy(plate, progress));
      if (name == "quadrature") results.push_back(run_quadrature_accuracy(quadrature, progress));
      if (name == "texture") results.push_back(run_texture_accuracy(texture, progress));
      if (name == "tolerance") results.push_back(run_tolerance_accuracy(tolerance, progress));
      if (name == "rotation") results.push_back(run_rotation_accuracy(rotation, progress));
      if (name == "scene_quadrature") results.push_back(run_scene_quadrature_accuracy(scene_quadrature, progress));
    }
    const std::filesystem::path dir(out_dir);
    write_output_file((dir / "accuracy.json").string(), accuracy_charts_json(results, machine, command), "--out");
    write_output_file((dir / "accuracy.md").string(), accuracy_charts_markdown(results, machine, command), "--out");
    int failed = 0;
    for (const AccuracyChart& chart : results) {
      const std::string path = (dir / ("accuracy_" + chart.name + "." + format)).string();
      const std::string failure = write_chart(path, chart, machine, command);
      if (failure.empty()) {
        std::printf("chart: %s\n", path.c_str());
      } else {
        std::fprintf(stderr, "dgtex bench accuracy: no chart %s: %s\n", path.c_str(), failure.c_str());
        ++failed;
      }
    }
    std::printf("data: %s, table: %s\n", (dir / "accuracy.json").string().c_str(), (dir / "accuracy.md").string().c_str());
    return failed ? 1 : 0;
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "dgtex bench accuracy: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dgtex bench accuracy: %s\n", e.what());
    return 1;
  }
}

}  // namespace dgtex::cli
