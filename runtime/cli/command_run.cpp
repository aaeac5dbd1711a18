// dgtex run SCENE --out DIR: simulate a scene and write its report, meshes and frames.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <omp.h>

#include "commands.h"
#include "dgtex/mesh_error.h"
#include "dgtex/mesh_output.h"
#include "dgtex/model_error.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_model.h"
#include "dgtex/shell_simulation.h"
#include "dgtex/surface_point.h"

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
  app.add_option("--out", out_dir, "output folder (created if missing)")->required();
  app.add_option("--threads", threads, "OpenMP threads (default: all cores)")->check(CLI::Range(1, 1024));
  app.add_flag("--quiet", quiet, "no progress line");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  if (threads > 0) omp_set_num_threads(threads);

  Scene scene;
  Mesh mesh;
  SceneModel setup;
  try {
    scene = load_scene(scene_path);
    if (!scene.cuts.empty())
      throw SceneError(scene.source_name, "cuts",
                       "cuts (enrichment textures) are not available in this version of dgtex yet", "", "an empty list");
    mesh = build_scene_mesh(scene);
    setup = build_scene_model(scene, mesh);
  } catch (const SceneError& e) {
    std::fprintf(stderr, "dgtex run: %s\n", e.what());
    return 2;
  } catch (const MeshError& e) {
    std::fprintf(stderr, "dgtex run: %s: mesh: %s\n", scene_path.c_str(), e.what());
    return 2;
  }
  const ShellModel& model = *setup.model;
  ShellSimulation sim(model, setup.fixed, setup.external_force);
  std::vector<fs::path> frames;
  const fs::path out(out_dir);
  try {
    fs::create_directories(out / "frames");
    if (!scene.analysis.is_dynamic()) {
      sim.solve_static();
    } else {
      DynamicsOptions options;
      options.time_step = scene.analysis.time_step;
      options.corotational = scene.analysis.corotational;
      options.mass_damping = scene.analysis.damping.mass;
      options.stiffness_damping = scene.analysis.damping.stiffness;
      const int every = scene.render ? scene.render->every_steps : 10;
      const bool progress = !quiet && isatty(fileno(stderr));
      write_vtu((out / "frames" / frame_name(0)).string(), mesh, sim.displacement().data());
      for (int step = 1; step <= scene.analysis.steps; ++step) {
        sim.step(options);
        if (!all_finite(sim.displacement()))
          throw ModelError("analysis: the solution diverged at step " + std::to_string(step) +
                           " (time step " + std::to_string(options.time_step) + " too large?)");
        if (step % every == 0 || step == scene.analysis.steps)
          write_vtu((out / "frames" / frame_name(step)).string(), mesh, sim.displacement().data());
        if (progress)
          std::fprintf(stderr, "\rdgtex run: step %d/%d  t = %.4g  %.1f ms/step", step, scene.analysis.steps,
                       sim.time(), (sim.timings().at("solve").total_ms + (sim.timings().count("assembly") ? sim.timings().at("assembly").total_ms : 0)) / step);
      }
      if (progress) std::fprintf(stderr, "\n");
    }
    write_vtu((out / "deformed.vtu").string(), mesh, sim.displacement().data());
  } catch (const ModelError& e) {
    std::fprintf(stderr, "dgtex run: %s: %s\n", scene_path.c_str(), e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "dgtex run: %s: %s\n", scene_path.c_str(), e.what());
    return 1;
  }

  nlohmann::json report;
  report["scene"] = scene_path;
  report["analysis"] = scene.analysis.is_dynamic() ? "dynamic" : "static";
  const std::int64_t lower = sim.system().nonzeros();
  report["counts"] = {{"elements", mesh.num_elements()},
                      {"nodes", mesh.num_nodes()},
                      {"dofs", model.num_dofs()},
                      {"free_dofs", sim.system().size()},
                      {"nonzeros", 2 * lower - sim.system().size()},
                      {"factor_nonzeros", sim.factor_nonzeros()},
                      {"interior_edges", model.num_interior_edges()},
                      {"clamped_edges", model.num_clamped_edges()},
                      {"quadrature_points", model.num_quadrature_points()},
                      {"enrichments", 0}};
  report["timings_ms"] = {{"assembly", stage_json(sim.timings(), "assembly")},
                          {"solve", stage_json(sim.timings(), "solve")}};
  report["time"] = sim.time();
  report["threads"] = omp_get_max_threads();
  nlohmann::json probes = nlohmann::json::object();
  for (const Probe& probe : scene.probes) {
    const SurfacePoint p = closest_surface_point(mesh, probe.position.data());
    double u[3];
    model.interpolate(sim.displacement(), p.element, p.xi, u);
    probes[probe.name] = {{"displacement", {u[0], u[1], u[2]}},
                          {"surface_point", {p.position[0], p.position[1], p.position[2]}},
                          {"element", p.element}};
  }
  report["probes"] = probes;
  const fs::path report_path = out / scene.output.report;
  std::ofstream file(report_path);
  file << report.dump(2) << "\n";
  if (!file) {
    std::fprintf(stderr, "dgtex run: cannot write %s\n", report_path.string().c_str());
    return 1;
  }
  if (!quiet) std::printf("dgtex run: wrote %s and %s\n", report_path.string().c_str(), (out / "deformed.vtu").string().c_str());
  return 0;
}

}  // namespace dgtex::cli
