// Scene quadrature sweep of dgtex bench accuracy: what the merge tolerance of the enriched
// quadrature (enrichment.quadrature_tolerance) costs in accuracy over a whole dynamic scene
// with cuts, and what it saves in time, set beside the scene's own time-step error.
#include <algorithm>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "dgtex/accuracy_benchmark.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"
#include "accuracy_scene_runs.h"
#include "api_argument_checks.h"

namespace dgtex {
namespace {

struct QuadratureRun {
  // The mesh nodes' (standard) DOFs after every `record_every`-th step; the last at the end.
  std::vector<std::vector<double>> node_path;
  double ms = 0, assembly_wall_ms = 0;
  std::int64_t quadrature_points = 0;  // enriched elements' and edges', at the end
};

// The scene's first `steps` steps, timed whole (set-up and cut updates included).
QuadratureRun run_scene(const Scene& scene, int steps, int record_every, AccuracyClock clock) {
  QuadratureRun out;
  const detail::TimedSceneRun timed = detail::run_scene_timed(scene, steps, clock, [&](const SceneRun& run, int k) {
    const auto& u = run.displacement();
    if (k % record_every == 0) out.node_path.emplace_back(u.begin(), u.begin() + 3 * run.mesh().num_nodes());
    if (k == steps)
      out.quadrature_points =
          run.model().num_enriched_element_quadrature_points() + run.model().num_enriched_edge_quadrature_points();
  });
  out.ms = timed.ms;
  out.assembly_wall_ms = timed.assembly_wall_ms;
  return out;
}

QuadratureRun run_at_tolerance(Scene scene, double tolerance, int steps, AccuracyClock clock) {
  scene.enrichment.quadrature_tolerance = tolerance;
  return run_scene(scene, steps, 1, clock);
}

// |u - u_ref| / |u_ref| over the mesh nodes after the last step (the chart's error), and
// the largest |u - u_ref| over the steps against the largest |u_ref| (early steps, where
// u_ref is near 0, would make a relative figure per step meaningless).
struct Difference {
  double final = 0, worst_in_run = 0;
};
Difference difference(const QuadratureRun& run, const QuadratureRun& reference) {
  using detail::relative_root, detail::squared_distance, detail::squared_norm;
  Difference d;
  d.final = relative_root(squared_distance(run.node_path.back(), reference.node_path.back()),
                          squared_norm(reference.node_path.back()));
  double worst = 0, largest = 0;
  for (std::size_t k = 0; k < reference.node_path.size(); ++k) {
    worst = std::max(worst, squared_distance(run.node_path[k], reference.node_path[k]));
    largest = std::max(largest, squared_norm(reference.node_path[k]));
  }
  d.worst_in_run = relative_root(worst, largest);
  return d;
}

std::string tolerance_label(double tolerance) {
  char text[32];
  std::snprintf(text, sizeof text, "tol=%g", tolerance);
  return text;
}

// The largest tolerance whose error stays below the time-step error, at the end and over
// the run. The error is not monotone in the tolerance (which cells merge changes with it),
// so smaller tolerances are not implied to pass too.
std::string affordable_tolerance(const std::vector<std::pair<double, Difference>>& swept,
                                 const Difference& time_step) {
  const std::pair<double, Difference>* best = nullptr;
  for (const auto& entry : swept)
    if (entry.second.final < time_step.final && entry.second.worst_in_run < time_step.worst_in_run &&
        (!best || entry.first > best->first))
      best = &entry;
  char text[320];
  if (!best) {
    std::snprintf(text, sizeof text,
                  "No swept tolerance stays below the time-step error (%.2g at the end, %.2g over the run).",
                  time_step.final, time_step.worst_in_run);
  } else {
    std::snprintf(text, sizeof text,
                  "The largest swept tolerance below the time-step error at the end and over the run: %g (%.2g and "
                  "%.2g against %.2g and %.2g).",
                  best->first, best->second.final, best->second.worst_in_run, time_step.final,
                  time_step.worst_in_run);
  }
  return text;
}

}  // namespace

void check_scene_quadrature_accuracy_options(const SceneQuadratureAccuracyOptions& options) {
  if (options.steps < 0)
    throw std::invalid_argument("scene quadrature accuracy: steps = " + std::to_string(options.steps) +
                                "; need >= 0 (0: the scene's own analysis.steps)");
  // The range of the scene's enrichment.quadrature_tolerance, which they become (inf was
  // refused by the scene's reader only once the sweep ran).
  auto in_scene_range = [](double t) { return t >= 1e-30 && t <= 1e30; };
  for (double t : options.tolerances)
    if (!in_scene_range(t))
      throw std::invalid_argument("scene quadrature accuracy: tolerance " + detail::short_number(t) +
                                  "; need 1e-30 <= tol <= 1e30");
  if (!in_scene_range(options.reference_tolerance))
    throw std::invalid_argument("scene quadrature accuracy: reference tolerance " +
                                detail::short_number(options.reference_tolerance) + "; need 1e-30 <= tol <= 1e30");
  // The errors are measured against the reference run: a looser reference (2 against 0.3)
  // charted the swept runs' distance to a less accurate run as their error.
  for (double t : options.tolerances)
    if (options.reference_tolerance > t)
      throw std::invalid_argument("scene quadrature accuracy: reference tolerance " +
                                  detail::short_number(options.reference_tolerance) +
                                  "; need one at or below every swept tolerance (" + detail::short_number(t) +
                                  " is swept)");
  const Scene scene = load_scene(options.scene);
  if (!scene.analysis.is_dynamic())
    throw std::invalid_argument("scene quadrature accuracy: " + options.scene + " is not a dynamic scene");
  // Without cuts no element is enriched: every tolerance gives the reference itself.
  if (scene.cuts.empty())
    throw std::invalid_argument("scene quadrature accuracy: " + options.scene +
                                " has no cuts; the merge tolerance applies to the quadrature of cut elements");
}

AccuracyChart run_scene_quadrature_accuracy(const SceneQuadratureAccuracyOptions& options,
                                            const AccuracyProgress& progress) {
  check_scene_quadrature_accuracy_options(options);
  const Scene scene = load_scene(options.scene);
  const int steps = options.steps > 0 ? options.steps : scene.analysis.steps;
  const std::string name = detail::scene_file_name(options.scene);
  AccuracyChart chart;
  chart.name = "scene_quadrature";
  chart.title = "merge tolerance of the enriched quadrature over a whole scene (" + name + ")";
  chart.time_label = accuracy_clock_name(options.clock) + " ms: the whole run (" + std::to_string(steps) +
                     " steps, cut updates included)";
  chart.error_label = "|u - u_ref| / |u_ref| at the mesh nodes after the run";
  // One point of the chart (and its progress line).
  auto add = [&](const std::string& series, const std::string& label, const QuadratureRun& run,
                 const Difference& error) {
    AccuracyPoint p;
    p.series = series;
    p.label = label;
    p.ms = run.ms;
    p.error = error.final;
    p.extra = {{"worst_error_in_run", error.worst_in_run},
               {"quadrature_points", static_cast<double>(run.quadrature_points)},
               {"assembly_wall_ms", run.assembly_wall_ms}};
    chart.points.push_back(p);
    if (!progress) return;
    char line[240];
    std::snprintf(line, sizeof line, "scene quadrature (%s) %s: %9.1f ms, %7lld points, error %.3e (worst in run %.3e)",
                  series.c_str(), label.c_str(), run.ms, static_cast<long long>(run.quadrature_points), error.final,
                  error.worst_in_run);
    progress(line);
  };
  const std::string tolerance_series = name + ", against " + tolerance_label(options.reference_tolerance);
  const double own_tolerance = scene.enrichment.quadrature_tolerance;
  const QuadratureRun reference = run_at_tolerance(scene, options.reference_tolerance, steps, options.clock);
  add(tolerance_series, tolerance_label(options.reference_tolerance), reference, Difference{});
  // The scene at its own tolerance, where the sweep runs it anyway.
  std::optional<QuadratureRun> own;
  if (own_tolerance == options.reference_tolerance) own = reference;
  std::vector<std::pair<double, Difference>> swept;
  for (double t : options.tolerances) {
    const QuadratureRun run = run_at_tolerance(scene, t, steps, options.clock);
    swept.emplace_back(t, difference(run, reference));
    add(tolerance_series, tolerance_label(t), run, swept.back().second);
    if (t == own_tolerance) own = run;
  }
  if (options.time_step_error) {
    // The scale the quadrature error is judged by: the scene at its own tolerance, against
    // the same scene at half the time step (twice the steps, the same end time).
    Scene halved = scene;
    halved.analysis.time_step /= 2;
    if (!own) own = run_scene(scene, steps, 1, options.clock);
    const QuadratureRun fine = run_scene(halved, 2 * steps, 2, options.clock);
    const Difference time_step_error = difference(*own, fine);
    add(name + ", time step against half of it", tolerance_label(own_tolerance) + " (the scene's)", *own,
        time_step_error);
    chart.conclusion = affordable_tolerance(swept, time_step_error);
    if (progress) progress("scene quadrature (" + name + "): " + chart.conclusion);
  }
  return chart;
}

}  // namespace dgtex
