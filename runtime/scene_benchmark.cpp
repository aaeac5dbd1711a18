#include "dgtex/scene_benchmark.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <map>
#include <stdexcept>

#include "dgtex/model_error.h"
#include "dgtex/scene_run.h"
#include "dgtex/stage_timer.h"

namespace dgtex {

namespace {

using Clock = std::chrono::steady_clock;



double stage_total(const StageTimings& timings, const char* stage) {
  const auto it = timings.find(stage);
  return it == timings.end() ? 0.0 : it->second.total_ms;
}

bool all_finite(const std::vector<double>& v) {
  for (double x : v)
    if (!std::isfinite(x)) return false;
  return true;
}

SceneCounts count(const Scene& scene, const SceneRun& run) {
  const ShellModel& model = run.model();
  const ShellSimulation& sim = run.simulation();
  SceneCounts c;
  c.elements = run.mesh().num_elements();
  c.nodes = run.mesh().num_nodes();
  c.dofs = model.num_dofs();
  c.enriched_dofs = model.num_enriched_dofs();
  c.free_dofs = sim.system().size();
  c.nonzeros = 2 * sim.system().nonzeros() - sim.system().size();  // both triangles, as `dgtex run`
  c.factor_nonzeros = sim.factor_nonzeros();
  c.interior_edges = model.num_interior_edges();
  c.clamped_edges = model.num_clamped_edges();
  c.quadrature_points = model.num_quadrature_points();
  c.enriched_elements = model.num_enriched_elements();
  c.enriched_quadrature_points =
      model.num_enriched_element_quadrature_points() + model.num_enriched_edge_quadrature_points();
  c.enrichments = static_cast<std::int64_t>(model.enrichments().size());
  c.texture_resolution = model.enrichments().empty() ? 0 : scene.enrichment.texture_resolution;
  c.basis_changes = run.basis_changes();
  c.rotation_clusters = model.num_rotation_clusters();
  c.rotation_cluster_bytes = model.rotation_cluster_bytes();
  return c;
}

}  // namespace

// Thesis "Discontinuous Galerkin FEM in Computer Graphics", §5.6, Table 5.1: "Comparison
// of timings for the computation of the enrichment functions (t_enr), assembly of the
// global stiffness matrix (t_asm), and solving the resulting linear system (t_sol).
// Timings are in milliseconds and were taken on an Intel Core2 Duo 2.4 GHz." The text
// below it: enrichment times are peak values, assembly and solve times averaged over the
// whole simulation. Columns: #Els., #Nodes, #Enr., Tex., t_enr, t_asm, t_sol.
// Our "fracture" scene (a tri6 rectangle of 544 elements torn by three cuts) stands in
// for the thesis's "Bunny" (a fractured triangle mesh of 552 elements, Fig. 5.1 right).
const ThesisTable51Row* thesis_table_5_1_row(const std::string& scene_name) {
  static const std::map<std::string, ThesisTable51Row> rows = {
      {"chad", {"Chad", 4, 21, 1, 256, 1433, 16, 3}},
      {"spiral1", {"Spiral 1", 1, 8, 1, 256, 274, 1.8, 0.1}},
      {"spiral6", {"Spiral 6", 1, 8, 6, 256, 1701, 38, 0.7}},
      {"accordion", {"Accordion", 1, 8, 18, 256, 4785, 313, 8}},
      {"fracture", {"Bunny", 552, 1106, 1, 32, 283, 452, 917}},
      {"slinky", {"Slinky", 4, 20, 12, 128, 5207, 513, 22}},
  };
  const auto it = rows.find(scene_name);
  return it == rows.end() ? nullptr : &it->second;
}

const std::vector<std::string>& bench_scene_names() {
  static const std::vector<std::string> names = {"chad",   "spiral1",  "spiral6",          "accordion",
                                                 "slinky", "fracture", "cylinder_buckling"};
  return names;
}

double series_mean(const std::vector<double>& v) {
  double sum = 0;
  for (double x : v) sum += x;
  return v.empty() ? 0.0 : sum / static_cast<double>(v.size());
}

double series_max(const std::vector<double>& v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); }

double series_median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double SceneBenchResult::steps_per_second() const {
  double total = 0;
  for (double ms : times.step) total += ms;
  return total > 0 ? 1e3 * static_cast<double>(times.step.size()) / total : 0.0;
}

double SceneBenchResult::peak_step_ms() const { return series_max(times.step); }

void check_scene_benchmark_scene(const Scene& scene) {
  if (!scene.analysis.is_dynamic())
    throw std::invalid_argument("scene '" + scene.source_name +
                                "' is a static analysis; the scene benchmark steps \"analysis\": {\"type\": \"dynamic\", ...}");
}

SceneBenchResult run_scene_benchmark(const Scene& scene, const std::string& name, int steps,
                                     const std::function<void(int, int)>& progress, const SceneRunOptions& options) {
  check_scene_benchmark_scene(scene);
  if (steps < 0) throw std::invalid_argument("steps = " + std::to_string(steps) + ", need >= 0 (0: the scene's own)");
  if (steps == 0) steps = scene.analysis.steps;

  SceneBenchResult result;
  result.name = name;
  result.path = scene.source_name;
  result.threads = omp_get_max_threads();
  result.overlap_cut_updates = options.overlap_cut_updates;

  const Clock::time_point setup_start = Clock::now();
  const double setup_cpu_start = process_cpu_ms();
  SceneRun run(scene, options);
  const double setup_ms = ms_since(setup_start), setup_cpu_ms = process_cpu_ms() - setup_cpu_start;
  // The time-0 enrichment update belongs to the first step (see the header).
  const double initial_enrichment_ms = stage_total(run.timings(), "enrichment");
  result.setup_ms = setup_ms - initial_enrichment_ms;
  // CPU time of the initial update, in proportion to its share of the setup's wall time.
  const double initial_enrichment_cpu_ms = setup_ms > 0 ? setup_cpu_ms * initial_enrichment_ms / setup_ms : 0.0;

  SceneStepTimes& t = result.times;
  FactorReuseStatistics counted = run.solver_statistics();
  StageTimings before = run.timings();
  before["enrichment"].total_ms -= initial_enrichment_ms;
  for (int step = 1; step <= steps; ++step) {
    const double cpu_start = process_cpu_ms();
    const Clock::time_point start = Clock::now();
    run.step();
    const double wall = ms_since(start), cpu = process_cpu_ms() - cpu_start;
    if (!all_finite(run.displacement()))
      throw ModelError("scene '" + name + "': the solution diverged at step " + std::to_string(step));
    const StageTimings after = run.timings();
    auto delta = [&](const char* stage) { return stage_total(after, stage) - stage_total(before, stage); };
    t.enrichment.push_back(delta("enrichment"));
    t.projection.push_back(delta("projection"));
    t.assembly.push_back(delta("assembly"));
    t.solve.push_back(delta("solve"));
    t.step.push_back(wall + (step == 1 ? initial_enrichment_ms : 0.0));
    t.step_cpu.push_back(cpu + (step == 1 ? initial_enrichment_cpu_ms : 0.0));
    before = after;
    const FactorReuseStatistics solver = run.solver_statistics();
    t.pcg_iterations.push_back(solver.iterations - counted.iterations);
    t.factorizations.push_back(solver.factorizations - counted.factorizations);
    counted = solver;
    t.cut_update_threads.push_back(run.last_cut_update_threads());
    if (progress) progress(step, steps);
  }
  result.steps = steps;
  result.scene_steps = scene.analysis.steps;
  result.counts = count(scene, run);
  result.settings = {scene.analysis.time_step, scene.enrichment.quadrature_tolerance,
                     scene.enrichment.rotation_cluster_texels};
  result.displacement = run.displacement();
  return result;
}

}  // namespace dgtex
