// dgtex run SCENE --out DIR: simulate a scene and write its report, meshes and frames.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <omp.h>
#include <new>
#include <string>
#include <vector>

#include "commands.h"
#include "count_option.h"
#include "dgtex/cut_surface_export.h"
#include "dgtex/frame_writer.h"
#include "dgtex/mesh_error.h"
#include "dgtex/mesh_output.h"
#include "dgtex/mesh_validation.h"
#include "dgtex/model_error.h"
#include "dgtex/model_memory_estimate.h"
#include "dgtex/penalty_caution.h"
#include "dgtex/point_caution.h"
#include "dgtex/rotation_caution.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"
#include "dgtex/selection_caution.h"
#include "dgtex/shell_state.h"
#include "dgtex/surface_point.h"
#include "dgtex/texel_memory_estimate.h"
#include "dgtex/version.h"
#include "api_argument_checks.h"
#include "interrupt_request.h"
#include "option_errors.h"
#include "output_paths.h"

namespace dgtex::cli {
namespace {

namespace fs = std::filesystem;

nlohmann::json stage_json(const StageTimings& timings, const std::string& stage) {
  const auto it = timings.find(stage);
  if (it == timings.end()) return {{"mean", 0.0}, {"max", 0.0}, {"calls", 0}};
  return {{"mean", it->second.mean_ms()}, {"max", it->second.max_ms}, {"calls", it->second.count}};
}

std::string frame_name(int index) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "frame_%05d.vtu", index);
  return buffer;
}

bool all_finite(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

}  // namespace

int run_command(int argc, char** argv) {
  CLI::App app{"Simulate a dgtex scene (JSON, version 1) and write DIR/report.json, meshes and frames", "dgtex run"};
  std::string scene_path, out_dir;
  int threads = 0;
  bool quiet = false;
  app.add_option("scene", scene_path, "scene file (JSON)")->required();
  app.add_option("--out", out_dir, "output folder (created if missing)")->required()->check(creatable_folder());
  app.add_option("--threads", threads, "OpenMP threads (default: all cores)")->check(thread_count());
  app.add_flag("--quiet", quiet, "no progress line");
  bool no_render = false, cut_surface_obj = false, save_textures = false, save_final_state = false,
       no_memory_reserve = false;
  app.add_flag("--no-render", no_render, "write no PNG frames even if the scene has a render block");
  app.add_flag("--obj", cut_surface_obj, "also write the final cut surface (split along cuts) to DIR/cut_surface.obj");
  app.add_flag("--save-state", save_final_state,
               "write the final state (mesh, displacement, enrichments) to DIR/final.state for dgtex render");
  app.add_flag("--save-textures", save_textures,
               "write the enrichment textures and cut walls of the final state to DIR/textures/enrichment.vdb");
  app.add_flag("--no-memory-reserve", no_memory_reserve,
               "do not fault in the memory of the first steps in the set-up (SceneRunOptions::reserve_step_memory)");
  try {
    app.parse(argc, argv);
    check_list_items(app, argc, argv);
  } catch (const CLI::ParseError& e) {
    return exit_on_option_error(app, e);
  }
  if (threads > 0) omp_set_num_threads(threads);
  // Progress: on a terminal the set-up and one line rewritten every step; into a log (not a
  // terminal) a step line every 10 s, so that a batch job's log shows the run advancing.
  const bool terminal = isatty(fileno(stderr));
  const bool progress = !quiet && terminal;
  bool progress_line_open = false;  // a rewritten step line waits for its newline

  Scene scene;
  std::unique_ptr<SceneRun> run;
  try {
    scene = load_scene(scene_path);
    check_report_name(scene);
    std::vector<InputFile> inputs = {{"the scene file", scene_path}};
    if (scene.mesh.source == MeshSource::file) inputs.push_back({"the scene's mesh.file", scene.mesh.file});
    for (size_t i = 0; i < scene.material_textures.size(); ++i)
      inputs.push_back({"the scene's material_textures[" + std::to_string(i) + "].image", scene.material_textures[i].image});
    check_run_outputs_spare_inputs(out_dir, scene.output.report, inputs);
    // The set-up (cut tracing, the first enrichment solves, the model) can take minutes
    // at a high texture_resolution: say so, then how long it took.
    const auto setup_start = std::chrono::steady_clock::now();
    if (progress) std::fprintf(stderr, "dgtex run: setting up the mesh, cuts and enrichment functions\n");
    // Near the memory limit the set-up can run for minutes before the system kills it: say
    // so before the fields are allocated (a scene that cannot fit at all is refused).
    SceneRunOptions run_options;
    const std::string model_caution = model_memory_caution(scene, available_memory_bytes());
    if (!model_caution.empty()) std::fprintf(stderr, "dgtex run: warning: %s: %s\n", scene_path.c_str(), model_caution.c_str());
    run_options.before_texel_fields = [&](const TexelFields& fields, std::int64_t available) {
      const std::string caution = texel_memory_caution(fields, available);
      if (!caution.empty()) std::fprintf(stderr, "dgtex run: warning: %s: %s\n", scene_path.c_str(), caution.c_str());
    };
    run_options.reserve_step_memory = !no_memory_reserve;
    run = std::make_unique<SceneRun>(scene, run_options);
    if (progress)
      std::fprintf(stderr, "dgtex run: set up in %.1f s\n",
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_start).count());
  } catch (const SceneError& e) {
    std::fprintf(stderr, "dgtex run: %s\n", e.what());
    return 2;
  } catch (const MeshError& e) {
    std::fprintf(stderr, "dgtex run: %s: mesh: %s\n", scene_path.c_str(), e.what());
    return 2;
  } catch (const ModelError& e) {
    std::fprintf(stderr, "dgtex run: %s: %s\n", scene_path.c_str(), e.what());
    return 2;
  } catch (const std::invalid_argument& e) {  // a cut the mesh cannot take (names cuts[i])
    std::fprintf(stderr, "dgtex run: %s: %s\n", scene_path.c_str(), e.what());
    return 2;
  } catch (const std::bad_alloc&) {  // past the memory guards' lower bounds (it aborted, SIGABRT)
    std::fprintf(stderr, "dgtex run: %s: out of memory in the set-up; a smaller mesh or texture_resolution, or more "
                 "memory\n", scene_path.c_str());
    return 1;
  }
  const Mesh& mesh = run->mesh();
  // Valid but likely not what was meant (dgtex/penalty_caution.h, selection_caution.h, point_caution.h,
  // mesh_validation.h): say so.
  if (const std::string caution = penalty_caution(scene.penalty, mesh.type); !caution.empty())
    std::fprintf(stderr, "dgtex run: warning: %s: %s\n", scene_path.c_str(), caution.c_str());
  if (const std::string caution = selection_tolerance_caution(scene, mesh); !caution.empty())
    std::fprintf(stderr, "dgtex run: warning: %s: %s\n", scene_path.c_str(), caution.c_str());
  if (const std::string caution = far_point_caution(scene, mesh); !caution.empty())
    std::fprintf(stderr, "dgtex run: warning: %s: %s\n", scene_path.c_str(), caution.c_str());
  if (run->simulation().system().size() == 0)  // ran, and wrote zeros, without a word
    std::fprintf(stderr, "dgtex run: warning: %s: boundary: every displacement is held (x, y and z of all %d nodes): "
                 "nothing can move\n", scene_path.c_str(), mesh.num_nodes());
  if (const std::string caution = unwelded_seam_caution(mesh); !caution.empty())
    std::fprintf(stderr, "dgtex run: warning: %s: mesh: %s\n", scene_path.c_str(), caution.c_str());
  // PNG frames (dgtex/frame_writer.h). The EGL context opens before the run, so a machine
  // without one fails here with one line and writes nothing.
  std::unique_ptr<FrameWriter> png_frames;
  if (scene.render && !no_render) {
    try {
      png_frames = std::make_unique<FrameWriter>(*scene.render, (fs::path(out_dir) / "frames").string());
    } catch (const EglUnavailableError& e) {
      std::fprintf(stderr, "dgtex run: %s\n", e.what());
      return 1;
    }
  }
  const fs::path out(out_dir);
  int vtu_frames = 0;
  // A linear run's largest rotation (dgtex/rotation_caution.h), read at every frame.
  const bool linear = !scene.analysis.is_dynamic() || !scene.analysis.corotational;
  LargestRotation largest_rotation_seen;
  int largest_rotation_step = 0;
  auto track_rotation = [&](int step) {
    const LargestRotation now = largest_rotation(mesh, run->displacement().data());
    if (now.value > largest_rotation_seen.value) {
      largest_rotation_seen = now;
      largest_rotation_step = step;
    }
  };
  auto write_frame = [&](int index) {
    write_vtu((out / "frames" / frame_name(index)).string(), mesh, run->displacement().data());
    if (linear) track_rotation(index);
    ++vtu_frames;
    if (png_frames) png_frames->write(run->state(), index);
  };
  std::vector<std::string> written;  // for the closing line
  int steps_completed = 0;
  int interrupted_by = 0;  // the signal that ended a dynamic run early
  // Once an earlier run's outputs are cleared, a failure also takes this run's own
  // frames: nothing that looks like a result stays behind.
  bool cleared = false;
  auto discard_this_runs_outputs = [&] {
    if (!cleared) return;
    try {
      remove_earlier_run_outputs(out_dir, scene.output.report);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "dgtex run: %s\n", e.what());
    }
  };
  try {
    // A static solve that fails (a penalty too low) is refused input: the folder stays as it was.
    if (!scene.analysis.is_dynamic()) run->solve_static();
    // frames/ holds VTU frames of dynamic runs and PNG frames of scenes with a render block.
    create_output_folder((scene.analysis.is_dynamic() || png_frames ? out / "frames" : out).string(), "--out");
    const int removed = remove_earlier_run_outputs(out_dir, scene.output.report);
    cleared = true;
    if (removed > 0 && !quiet)
      std::fprintf(stderr, "dgtex run: removed %d files of an earlier run from %s\n", removed, out_dir.c_str());
    if (!scene.analysis.is_dynamic()) {
      if (linear) track_rotation(0);
      if (png_frames) png_frames->write(run->state(), 0);
    } else {
      const int every = scene.render ? scene.render->every_steps : 10;
      write_frame(0);
      auto last_log_line = std::chrono::steady_clock::now();
      const InterruptRequest interrupt;
      for (int step = 1; step <= scene.analysis.steps; ++step) {
        try {
          run->step();
        } catch (const std::invalid_argument& e) {  // the scene, met in a step: a progressive cut's new function
          throw ModelError("step " + std::to_string(step) +
                           " (to t = " + detail::short_number(step * scene.analysis.time_step) + "): " + e.what());
        } catch (const ModelError&) {
          throw;
        } catch (const std::runtime_error& e) {  // a failed step (a diverged state): which one
          throw std::runtime_error("step " + std::to_string(step) + " (to t = " +
                                   detail::short_number(step * scene.analysis.time_step) + "): " + e.what());
        }
        if (!all_finite(run->displacement()))
          throw ModelError("analysis: the solution diverged at step " + std::to_string(step) + " (time step " +
                           std::to_string(scene.analysis.time_step) + " too large?)");
        steps_completed = step;
        const bool stop_early = interrupt.signal() != 0 && step < scene.analysis.steps;
        if (step % every == 0 || step == scene.analysis.steps || stop_early) write_frame(step);
        const auto now = std::chrono::steady_clock::now();
        const bool log_line = !quiet && !terminal && now - last_log_line >= std::chrono::seconds(10);
        if (progress || log_line) {
          double ms = 0;
          for (const auto& [stage, stats] : run->timings()) ms += stats.total_ms;
          std::fprintf(stderr, "%sdgtex run: step %d/%d  t = %.4g  %.1f ms/step  enrichments %d%s",
                       progress ? "\r" : "", step, scene.analysis.steps, run->time(), ms / step,
                       static_cast<int>(run->model().enrichments().size()), progress ? "   " : "\n");
          progress_line_open = progress;
          if (log_line) last_log_line = now;
        }
        if (stop_early) {
          interrupted_by = interrupt.signal();
          break;
        }
      }
      if (progress_line_open) std::fprintf(stderr, "\n");
      progress_line_open = false;
    }
    write_vtu((out / "deformed.vtu").string(), mesh, run->displacement().data());
    written.push_back("deformed.vtu");
    if (vtu_frames > 0) written.push_back(std::to_string(vtu_frames) + " VTU frames");
    if (png_frames) written.push_back(std::to_string(png_frames->frames_written()) + " PNG frames");
    if (cut_surface_obj) {
      export_cut_surface_obj((out / "cut_surface.obj").string(), run->state());
      written.push_back("cut_surface.obj");
    }
    if (save_textures && run->cuts()) {
      run->cuts()->save_textures((out / "textures").string());
      written.push_back("textures/enrichment.vdb");
    } else if (save_textures) {
      std::fprintf(stderr, "dgtex run: note: --save-textures writes the textures of cuts, and the scene has none\n");
    }
    if (save_final_state) {
      save_state((out / "final.state").string(), run->state());
      written.push_back("final.state");
    }
  } catch (const ModelError& e) {
    std::fprintf(stderr, "%sdgtex run: %s: %s\n", progress_line_open ? "\n" : "", scene_path.c_str(), e.what());
    discard_this_runs_outputs();
    return 2;
  } catch (const std::bad_alloc&) {  // past the set-up's memory checks, which are lower bounds
    std::fprintf(stderr, "%sdgtex run: %s: out of memory after %d of %d steps; a smaller texture_resolution, fewer "
                 "enriched elements, or more memory (ulimit -v, the container's limit)\n", progress_line_open ? "\n" : "",
                 scene_path.c_str(), steps_completed, scene.analysis.is_dynamic() ? scene.analysis.steps : 1);
    discard_this_runs_outputs();
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%sdgtex run: %s: %s\n", progress_line_open ? "\n" : "", scene_path.c_str(), e.what());
    discard_this_runs_outputs();
    return 1;
  }

  const ShellModel& model = run->model();
  const ShellSimulation& sim = run->simulation();
  const StageTimings timings = run->timings();
  nlohmann::json report;
  report["dgtex_version"] = version();  // which build wrote it
  report["scene"] = scene_path;
  report["analysis"] = scene.analysis.is_dynamic() ? "dynamic" : "static";
  report["completed"] = interrupted_by == 0;
  if (scene.analysis.is_dynamic()) report["steps_completed"] = steps_completed;
  if (interrupted_by != 0) report["interrupted_by"] = signal_name(interrupted_by);
  const std::int64_t lower = sim.system().nonzeros();
  report["counts"] = {{"elements", mesh.num_elements()},
                      {"nodes", mesh.num_nodes()},
                      {"dofs", model.num_dofs()},
                      {"enriched_dofs", model.num_enriched_dofs()},
                      {"free_dofs", sim.system().size()},
                      {"nonzeros", 2 * lower - sim.system().size()},
                      {"factor_nonzeros", sim.factor_nonzeros()},
                      {"interior_edges", model.num_interior_edges()},
                      {"clamped_edges", model.num_clamped_edges()},
                      {"quadrature_points", model.num_quadrature_points()},
                      {"enriched_elements", model.num_enriched_elements()},
                      {"enriched_quadrature_points", model.num_enriched_element_quadrature_points() +
                                                         model.num_enriched_edge_quadrature_points()},
                      {"enrichments", static_cast<int>(model.enrichments().size())},
                      {"texture_resolution", model.enrichments().empty() ? 0 : scene.enrichment.texture_resolution},
                      {"basis_changes", run->basis_changes()},
                      {"rotation_clusters", model.num_rotation_clusters()},
                      {"rotation_cluster_bytes", model.rotation_cluster_bytes()}};
  report["timings_ms"] = {{"enrichment", stage_json(timings, "enrichment")},
                          {"projection", stage_json(timings, "projection")},
                          {"assembly", stage_json(timings, "assembly")},
                          {"solve", stage_json(timings, "solve")}};
  report["timings_ms"]["render"] = stage_json(png_frames ? png_frames->timings() : StageTimings{}, "render");
  const FactorReuseStatistics solver = run->solver_statistics();
  report["solver"] = {{"solves", solver.solves},
                      {"pcg_iterations", solver.iterations},
                      {"factorizations", solver.factorizations},
                      {"stale_factor_failures", solver.stale_factor_failures},
                      {"element_local_fallbacks", solver.element_local_fallbacks}};
  // A reused factor that keeps failing means the step matrix changes fast from step to step:
  // worth a look at the result (fracture's unstable near-massless mode showed up this way).
  if (solver.stale_factor_failures >= 5 && solver.stale_factor_failures * 20 > solver.solves)
    std::fprintf(stderr,
                 "dgtex run: warning: the step solver's reused factor failed in %ld of %ld solves (the system "
                 "changes fast from step to step, e.g. a mode with almost no mass going unstable); check the "
                 "result, see README \"Stability where methods fail\"\n",
                 solver.stale_factor_failures, solver.solves);
  const std::string when = scene.analysis.is_dynamic() ? "at step " + std::to_string(largest_rotation_step) : "";
  if (const std::string caution = linear_rotation_caution(largest_rotation_seen, when); !caution.empty())
    std::fprintf(stderr, "dgtex run: warning: %s: %s\n", scene_path.c_str(), caution.c_str());
  report["time"] = run->time();
  report["threads"] = omp_get_max_threads();
  report["reserved_step_memory_bytes"] = run->reserved_step_memory_bytes();
  nlohmann::json probes = nlohmann::json::object();
  for (const Probe& probe : scene.probes) {
    const SurfacePoint p = closest_surface_point(mesh, probe.position.data());
    double u[3];
    model.interpolate(run->displacement(), p.element, p.xi, u);
    probes[probe.name] = {{"displacement", {u[0], u[1], u[2]}},
                          {"surface_point", {p.position[0], p.position[1], p.position[2]}},
                          {"element", p.element}};
  }
  report["probes"] = probes;
  const fs::path report_path = out / scene.output.report;
  std::ofstream file(report_path);
  file << report.dump(2) << "\n";
  file.close();  // a full disk shows only when the buffer is written out
  if (!file) {
    std::fprintf(stderr, "dgtex run: cannot write %s\n", report_path.string().c_str());
    return 1;
  }
  if (!quiet) {
    std::string list = scene.output.report;
    for (const std::string& item : written) list += ", " + item;
    std::printf("dgtex run: wrote into %s: %s\n", out.string().c_str(), list.c_str());
  }
  if (interrupted_by != 0) {
    std::fprintf(stderr, "dgtex run: %s: interrupted by %s at step %d of %d (t = %s); the results are that step's\n",
                 scene_path.c_str(), signal_name(interrupted_by), steps_completed, scene.analysis.steps,
                 detail::short_number(run->time()).c_str());
    return 128 + interrupted_by;  // the shell's convention for a process ended by a signal
  }
  return 0;
}

}  // namespace dgtex::cli
