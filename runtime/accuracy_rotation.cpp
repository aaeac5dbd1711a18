// Rotation sweep of dgtex bench accuracy: what the rotation clusters of enriched elements
// (enrichment.rotation_cluster_texels, dgtex/kernels/enriched_rotation_clusters.h) cost in
// accuracy against the per-point corotation, and what they save in time.
#include <cstdio>
#include <stdexcept>
#include <string>

#include "dgtex/accuracy_benchmark.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_run.h"
#include "accuracy_scene_runs.h"

namespace dgtex {
namespace {

struct RotationRun {
  std::vector<double> displacement;
  double ms = 0, assembly_wall_ms = 0;
  std::int64_t clusters = 0, cluster_bytes = 0;
};

// The scene's first `steps` steps with the given clusters (0: per point), timed whole.
RotationRun run_scene(const Scene& base, int block_texels, int steps, AccuracyClock clock) {
  Scene scene = base;
  scene.enrichment.rotation_cluster_texels = block_texels;
  RotationRun out;
  const detail::TimedSceneRun timed = detail::run_scene_timed(scene, steps, clock, [&](const SceneRun& run, int k) {
    if (k < steps) return;
    out.displacement = run.displacement();
    out.clusters = run.model().num_rotation_clusters();
    out.cluster_bytes = run.model().rotation_cluster_bytes();
  });
  out.ms = timed.ms;
  out.assembly_wall_ms = timed.assembly_wall_ms;
  return out;
}

}  // namespace

void check_rotation_accuracy_options(const RotationAccuracyOptions& options) {
  if (options.steps < 1)
    throw std::invalid_argument("rotation accuracy: rotation steps = " + std::to_string(options.steps) + "; need >= 1");
  for (int b : options.block_texels)  // the scene's enrichment.rotation_cluster_texels, 0 (per point) excluded
    if (b < 1 || b > 4096)
      throw std::invalid_argument("rotation accuracy: rotation block B = " + std::to_string(b) +
                                  " texels; need 1..4096");
  const Scene base = load_scene(options.scene);
  if (!base.analysis.is_dynamic() || !base.analysis.corotational)
    throw std::invalid_argument("rotation accuracy: " + options.scene + " is not a dynamic corotated scene");
  // Clusters group the points of enriched elements only: without cuts every block size
  // gives the per-point run itself (error 0, which the log-scale chart cannot draw).
  if (base.cuts.empty())
    throw std::invalid_argument("rotation accuracy: " + options.scene +
                                " has no cuts; rotation clusters group the quadrature points of cut elements");
}

AccuracyChart run_rotation_accuracy(const RotationAccuracyOptions& options, const AccuracyProgress& progress) {
  check_rotation_accuracy_options(options);
  const Scene base = load_scene(options.scene);
  AccuracyChart chart;
  chart.name = "rotation";
  chart.title = "rotation clusters of enriched elements against time";
  chart.time_label = accuracy_clock_name(options.clock) + " ms: the whole run (" + std::to_string(options.steps) +
                     " steps, rest sums of the clusters included)";
  chart.error_label = "|u - u_ref| / |u_ref| vs per-point rotations";
  const std::string series = detail::scene_file_name(options.scene);
  const RotationRun reference = run_scene(base, 0, options.steps, options.clock);
  const double reference_norm = detail::squared_norm(reference.displacement);
  auto add = [&](const std::string& label, const RotationRun& run) {
    if (run.displacement.size() != reference.displacement.size())
      throw std::logic_error("rotation accuracy: DOF counts of the runs differ");
    AccuracyPoint p;
    p.series = series;
    p.label = label;
    p.ms = run.ms;
    p.error = detail::relative_root(detail::squared_distance(run.displacement, reference.displacement), reference_norm);
    p.extra = {{"clusters", static_cast<double>(run.clusters)},
               {"cluster_mb", run.cluster_bytes / 1e6},
               {"assembly_wall_ms", run.assembly_wall_ms}};
    chart.points.push_back(p);
    if (progress) {
      char line[200];
      std::snprintf(line, sizeof line, "rotation %-12s: %9.1f ms, %5lld clusters (%7.1f MB), error %.3e", label.c_str(),
                    p.ms, static_cast<long long>(run.clusters), run.cluster_bytes / 1e6, p.error);
      progress(line);
    }
  };
  add("per point", reference);
  for (int b : options.block_texels) add("B=" + std::to_string(b), run_scene(base, b, options.steps, options.clock));
  return chart;
}

}  // namespace dgtex
