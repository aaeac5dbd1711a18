// Quadrature sweep of dgtex bench accuracy: a 1 x 1 plate of 2 x 2 elements (quad8, or 8
// tri6), pinned on all four sides, under uniform pressure, with a partial cut along a circular
// arc (radius 0.3 about the centre, 270 degrees, open to -x) that crosses all four cells,
// so H varies smoothly away from the cut and sharply along it and near the tips. The
// enrichment functions are computed once (CHOLMOD); then, per merge tolerance of the
// adaptive enriched quadrature and for the per-texel rule, a fresh model takes them, the
// static solve gives the compliance f.u, and one linear stiffness assembly is timed.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>

#include "dgtex/accuracy_benchmark.h"
#include "dgtex/scene_io.h"
#include "dgtex/scene_model.h"
#include "dgtex/scene_run.h"
#include "dgtex/shell_simulation.h"
#include "dgtex/topology.h"
#include "api_argument_checks.h"

namespace dgtex {
namespace {

std::string arc_cut_scene(const std::string& element, int resolution) {
  const double pi = 3.14159265358979323846, radius = 0.3;
  std::ostringstream points;
  const int count = 48;
  for (int k = 0; k <= count; ++k) {
    const double angle = (-135.0 + 270.0 * k / count) * pi / 180;
    points << (k ? ", " : "") << "[" << 0.5 + radius * std::cos(angle) << ", " << 0.5 + radius * std::sin(angle)
           << ", 0]";
  }
  std::ostringstream s;
  s << R"({"mesh": {"generator": "rectangle", "size": [1, 1], "divisions": [2, 2], "element": ")" << element << R"("},
  "material": {"youngs_modulus": 1e6, "poisson_ratio": 0.3, "thickness": 0.01, "density": 1000},
  "penalty": 1,
  "boundary": [
    {"select": {"plane": {"normal": [1, 0, 0], "offset": 0}}, "fix": ["x", "y", "z"]},
    {"select": {"plane": {"normal": [1, 0, 0], "offset": 1}}, "fix": ["x", "y", "z"]},
    {"select": {"plane": {"normal": [0, 1, 0], "offset": 0}}, "fix": ["x", "y", "z"]},
    {"select": {"plane": {"normal": [0, 1, 0], "offset": 1}}, "fix": ["x", "y", "z"]}],
  "loads": [{"type": "area_force", "force_per_area": [0, 0, -1]}],
  "analysis": {"type": "static"},
  "cuts": [{"points": [)" << points.str() << R"(]}],
  "enrichment": {"texture_resolution": )" << resolution << R"(, "solver": "cholmod"}})";
  return s.str();
}

struct QuadratureCase {
  double compliance = 0;
  double assembly_ms = std::numeric_limits<double>::infinity();  // best of repeat
  double rule_ms = 0;  // model construction + set_enrichments (builds the rule)
  std::int64_t points = 0;
};

QuadratureCase run_case(const Scene& scene, const ShellModel& base, const std::vector<EnrichmentFunction>& functions,
                        const kernels::EnrichedQuadratureOptions& quadrature, int repeat, AccuracyClock clock) {
  QuadratureCase out;
  const double start = accuracy_clock_ms(clock);
  ShellModelOptions options = base.options();
  options.enrichment_quadrature = quadrature;
  ShellModel model(base.mesh(), build_topology(base.mesh()), base.sections(), {}, options);
  model.set_enrichments(functions);
  out.rule_ms = accuracy_clock_ms(clock) - start;
  out.points = model.num_enriched_element_quadrature_points();
  std::vector<double> blocks;
  for (int r = 0; r < std::max(1, repeat); ++r) {
    const double t = accuracy_clock_ms(clock);
    model.assemble_stiffness(nullptr, blocks, nullptr);
    out.assembly_ms = std::min(out.assembly_ms, accuracy_clock_ms(clock) - t);
  }
  const std::vector<double> f = scene_external_force(scene, model);
  ShellSimulation simulation(model, scene_fixed_dofs(scene, model), f);
  simulation.solve_static();
  const std::vector<double>& u = simulation.displacement();
  out.compliance = std::inner_product(f.begin(), f.end(), u.begin(), 0.0);
  return out;
}

}  // namespace

void check_quadrature_accuracy_options(const QuadratureAccuracyOptions& options) {
  // T becomes the arc-cut scene's enrichment.texture_resolution: a power of two in 8..4096
  // (T = 100 was refused by that scene's reader only once the sweep ran, as exit code 1).
  const int T = options.resolution;
  if (!is_texture_resolution(T))
    throw std::invalid_argument("quadrature resolution T = " + std::to_string(T) +
                                "; need a power of two in 8..4096 (8, 16, ..., 4096)");
  // The range of the scene's enrichment.quadrature_tolerance, which they become (inf failed
  // in the sweep; 1e-300 ran, and the chart's log axis failed in gnuplot, exit code 1).
  for (double tol : options.tolerances)
    if (!(tol >= 1e-30 && tol <= 1e30))
      throw std::invalid_argument("quadrature tolerance " + detail::short_number(tol) + "; need 1e-30 <= tol <= 1e30");
  for (const std::string& e : options.elements)
    if (e != "quad8" && e != "tri6")
      throw std::invalid_argument("quadrature element '" + e + "'; valid: quad8, tri6");
}

AccuracyChart run_quadrature_accuracy(const QuadratureAccuracyOptions& options, const AccuracyProgress& progress) {
  check_quadrature_accuracy_options(options);
  AccuracyChart chart;
  chart.name = "quadrature";
  chart.title = "enriched quadrature: merge tolerance (plate with an arc cut, T = " +
                std::to_string(options.resolution) + ")";
  chart.time_label = "one linear stiffness assembly (" + accuracy_clock_name(options.clock) + " ms)";
  chart.error_label = "relative error of the compliance f.u vs the per-texel rule";
  for (const std::string& element : options.elements) {
    const Scene scene = parse_scene(arc_cut_scene(element, options.resolution), "accuracy-quadrature-" + element);
    const SceneRun run(scene);  // traces the cut and solves its enrichment at time 0
    const std::vector<EnrichmentFunction>& functions = run.model().enrichments();
    if (functions.empty()) throw std::logic_error("quadrature accuracy: the arc cut produced no enrichment");
    kernels::EnrichedQuadratureOptions per_texel;
    per_texel.adaptive = false;
    const QuadratureCase reference = run_case(scene, run.model(), functions, per_texel, options.repeat, options.clock);
    auto report = [&](const std::string& label, const QuadratureCase& c, double error) {
      AccuracyPoint p;
      p.series = element;
      p.label = label;
      p.ms = c.assembly_ms;
      p.error = error;
      p.extra = {{"quadrature_points", static_cast<double>(c.points)}, {"rule_ms", c.rule_ms},
                 {"compliance", c.compliance}};
      chart.points.push_back(p);
      if (progress) {
        char line[200];
        std::snprintf(line, sizeof line, "quadrature %s %-12s: assembly %8.2f ms, %8lld enriched points, error %.3e",
                      element.c_str(), label.c_str(), c.assembly_ms, static_cast<long long>(c.points), error);
        progress(line);
      }
    };
    report("per-texel", reference, 0.0);
    for (double tol : options.tolerances) {
      kernels::EnrichedQuadratureOptions adaptive;
      adaptive.merge_tolerance = tol;
      const QuadratureCase c = run_case(scene, run.model(), functions, adaptive, options.repeat, options.clock);
      char label[32];
      std::snprintf(label, sizeof label, "tol=%g", tol);
      report(label, c, std::abs(c.compliance / reference.compliance - 1));
    }
  }
  return chart;
}

}  // namespace dgtex
