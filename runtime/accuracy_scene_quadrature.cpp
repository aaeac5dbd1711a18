// Scene quadrature sweep of dgtex bench accuracy: what the merge tolerance of the enriched
// quadrature (enrichment.quadrature_tolerance) costs in accuracy over a whole dynamic scene
// with cuts, and what it saves in time, set beside the scene's own time-step error.
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>

#include "dgtex/accuracy_benchmark.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"

namespace dgtex {
namespace {

struct QuadratureRun {
  std::vector<double> node_displacement;  // the mesh nodes' (standard) DOFs at the end
  double ms = 0, assembly_wall_ms = 0;
  std::int64_t quadrature_points = 0;  // enriched elements' and edges', at the end
};

// The scene's first `steps` steps, timed whole (set-up and cut updates included).
QuadratureRun run_scene(const Scene& scene, int steps, AccuracyClock clock) {
  QuadratureRun out;
  const double start = accuracy_clock_ms(clock);
  SceneRun run(scene);
  for (int k = 0; k < steps; ++k) run.step();
  out.ms = accuracy_clock_ms(clock) - start;
  const std::vector<double>& u = run.displacement();
  out.node_displacement.assign(u.begin(), u.begin() + 3 * run.mesh().num_nodes());
  const StageTimings timings = run.timings();
  if (const auto it = timings.find("assembly"); it != timings.end()) out.assembly_wall_ms = it->second.total_ms;
  out.quadrature_points =
      run.model().num_enriched_element_quadrature_points() + run.model().num_enriched_edge_quadrature_points();
  return out;
}

QuadratureRun run_at_tolerance(Scene scene, double tolerance, int steps, AccuracyClock clock) {
  scene.enrichment.quadrature_tolerance = tolerance;
  return run_scene(scene, steps, clock);
}

// |u - u_ref| / |u_ref| over the mesh nodes.
double relative_difference(const QuadratureRun& run, const QuadratureRun& reference) {
  double diff = 0, norm = 0;
  for (std::size_t k = 0; k < reference.node_displacement.size(); ++k) {
    const double d = run.node_displacement[k] - reference.node_displacement[k];
    diff += d * d;
    norm += reference.node_displacement[k] * reference.node_displacement[k];
  }
  return norm > 0 ? std::sqrt(diff / norm) : std::sqrt(diff);
}

std::string tolerance_label(double tolerance) {
  char text[32];
  std::snprintf(text, sizeof text, "tol=%g", tolerance);
  return text;
}

}  // namespace

AccuracyChart run_scene_quadrature_accuracy(const SceneQuadratureAccuracyOptions& options,
                                            const AccuracyProgress& progress) {
  if (options.steps < 0)
    throw std::invalid_argument("scene quadrature accuracy: steps = " + std::to_string(options.steps) +
                                "; need >= 0 (0: the scene's own analysis.steps)");
  for (double t : options.tolerances)
    if (!(t > 0))
      throw std::invalid_argument("scene quadrature accuracy: tolerance " + std::to_string(t) + "; need > 0");
  if (!(options.reference_tolerance > 0))
    throw std::invalid_argument("scene quadrature accuracy: reference tolerance " +
                                std::to_string(options.reference_tolerance) + "; need > 0");
  const Scene scene = load_scene(options.scene);
  if (!scene.analysis.is_dynamic())
    throw std::invalid_argument("scene quadrature accuracy: " + options.scene + " is not a dynamic scene");
  // Without cuts no element is enriched: every tolerance gives the reference itself.
  if (scene.cuts.empty())
    throw std::invalid_argument("scene quadrature accuracy: " + options.scene +
                                " has no cuts; the merge tolerance applies to the quadrature of cut elements");
  const int steps = options.steps > 0 ? options.steps : scene.analysis.steps;
  const std::string name = options.scene.substr(options.scene.find_last_of('/') + 1);
  AccuracyChart chart;
  chart.name = "scene_quadrature";
  chart.title = "merge tolerance of the enriched quadrature over a whole scene (" + name + ")";
  chart.time_label = accuracy_clock_name(options.clock) + " ms: the whole run (" + std::to_string(steps) +
                     " steps, cut updates included)";
  chart.error_label = "|u - u_ref| / |u_ref| at the mesh nodes after the run";
  auto report = [&](const AccuracyPoint& p, std::int64_t points) {
    chart.points.push_back(p);
    if (!progress) return;
    char line[240];
    std::snprintf(line, sizeof line, "scene quadrature (%s) %s: %9.1f ms, %7lld points, error %.3e",
                  p.series.c_str(), p.label.c_str(), p.ms, static_cast<long long>(points), p.error);
    progress(line);
  };
  auto point = [](const std::string& series, const std::string& label, const QuadratureRun& run, double error) {
    AccuracyPoint p;
    p.series = series;
    p.label = label;
    p.ms = run.ms;
    p.error = error;
    p.extra = {{"quadrature_points", static_cast<double>(run.quadrature_points)},
               {"assembly_wall_ms", run.assembly_wall_ms}};
    return p;
  };
  const std::string tolerance_series = name + ", against " + tolerance_label(options.reference_tolerance);
  const double own_tolerance = scene.enrichment.quadrature_tolerance;
  std::optional<QuadratureRun> own;  // the scene at its own tolerance, if the sweep has it
  const QuadratureRun reference = run_at_tolerance(scene, options.reference_tolerance, steps, options.clock);
  report(point(tolerance_series, tolerance_label(options.reference_tolerance), reference, 0.0),
         reference.quadrature_points);
  for (double t : options.tolerances) {
    const QuadratureRun run = run_at_tolerance(scene, t, steps, options.clock);
    const double error = relative_difference(run, reference);
    report(point(tolerance_series, tolerance_label(t), run, error), run.quadrature_points);
    if (t == own_tolerance) own = run;
  }
  if (options.time_step_error) {
    // The scale the quadrature error is judged by: the scene at its own tolerance, against
    // the same scene at half the time step (twice the steps, the same end time).
    Scene halved = scene;
    halved.analysis.time_step /= 2;
    if (!own) own = run_scene(scene, steps, options.clock);
    const QuadratureRun fine = run_scene(halved, 2 * steps, options.clock);
    report(point(name + ", time step against half of it", tolerance_label(own_tolerance) + " (the scene's)", *own,
                 relative_difference(*own, fine)),
           own->quadrature_points);
  }
  return chart;
}

}  // namespace dgtex
