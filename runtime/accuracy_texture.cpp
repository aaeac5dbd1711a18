// Texture sweep of dgtex bench accuracy (thesis Fig. 5.13 at growing T): on a T x T tile
// (the unit element) a straight cut runs from the west border to the centre; the texels
// beside it get +-sqrt(r) (r from the tip, texel units) and the outermost texel ring the
// exact crack-tip field f = sqrt(r) sin(theta / 2). The harmonic solution converges to f
// away from the tip; the error is measured in a fixed annulus of the element, so it shrinks
// as T grows (the annulus lies more texels away from the singularity).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

#include "dgtex/accuracy_benchmark.h"
#include "dgtex/harmonic_enrichment.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/laplace_solver.h"
#include "dgtex/scene.h"

namespace dgtex {
namespace {

double crack_tip_field(double x, double y, double tip) {
  return std::sqrt(std::hypot(x - tip, y - tip)) * std::sin(0.5 * std::atan2(y - tip, x - tip));
}

struct CrackTipProblem {
  kernels::TexelTile tile;  // walls of the cut, outer ring Dirichlet with f
  kernels::CutRaster cut;
  double tip = 0;
  CutSideValue side_value;
};

CrackTipProblem make_problem(int T) {
  CrackTipProblem p;
  p.tile = kernels::TexelTile(T, T);
  p.tip = T / 2.0;
  p.cut = kernels::rasterize_cut({{0.0, p.tip}, {p.tip, p.tip}}, p.tile);
  for (int j = 0; j < T; ++j)
    for (int i = 0; i < T; ++i)
      if (i == 0 || j == 0 || i == T - 1 || j == T - 1) {
        p.tile.flags[p.tile.index(i, j)] |= kernels::dirichlet;
        p.tile.values[p.tile.index(i, j)] = crack_tip_field(i + 0.5, j + 0.5, p.tip);
      }
  const double tip = p.tip;
  p.side_value = [T, tip](int texel, int side) {
    return side * std::sqrt(std::hypot(texel % T + 0.5 - tip, texel / T + 0.5 - tip));
  };
  return p;
}

struct TipError {
  double max = 0, rms = 0;
  int texels = 0;
};

TipError tip_error(const kernels::TexelTile& solution, double tip, double r_min, double r_max) {
  const int T = solution.width;
  TipError e;
  double sum = 0;
  for (int j = 0; j < T; ++j)
    for (int i = 0; i < T; ++i) {
      const double x = i + 0.5, y = j + 0.5, r = std::hypot(x - tip, y - tip);
      if (r < r_min * T || r > r_max * T) continue;
      const double ratio = std::abs(solution.values[solution.index(i, j)] - crack_tip_field(x, y, tip)) / std::sqrt(r);
      e.max = std::max(e.max, ratio);
      sum += ratio * ratio;
      ++e.texels;
    }
  if (e.texels == 0)
    throw std::invalid_argument("texture accuracy: no texel centre in the annulus " + std::to_string(r_min) + " <= r <= " +
                                std::to_string(r_max) + " at T = " + std::to_string(T));
  e.rms = std::sqrt(sum / e.texels);
  return e;
}

// At most the largest texture a scene takes (enrichment.texture_resolution), as in dgtex
// bench laplace: T = 100000 ended the sweep in a bare std::bad_alloc.
void check_resolution(int T) {
  if (T < 16 || T > kMaxTextureResolution || T % 2)
    throw std::invalid_argument("texture size T = " + std::to_string(T) + "; need an even T in 16..4096");
}

}  // namespace

double crack_tip_texture_error(int resolution, double r_min, double r_max) {
  check_resolution(resolution);
  const CrackTipProblem p = make_problem(resolution);
  const HarmonicEnrichment h = harmonic_enrichment(p.tile, p.cut, p.side_value);
  return tip_error(h.tile, p.tip, r_min, r_max).max;
}

void check_texture_accuracy_options(const TextureAccuracyOptions& options) {
  for (int T : options.resolutions) check_resolution(T);
  if (!(options.r_min > 0 && options.r_min < options.r_max && options.r_max <= 0.5))
    throw std::invalid_argument("texture accuracy annulus: need 0 < r_min < r_max <= 0.5 (element lengths)");
}

AccuracyChart run_texture_accuracy(const TextureAccuracyOptions& options, const AccuracyProgress& progress) {
  check_texture_accuracy_options(options);
  AccuracyChart chart;
  chart.name = "texture";
  chart.title = "texture resolution: +-sqrt(r) harmonic enrichment vs sqrt(r) sin(theta/2)";
  chart.time_label = "Laplace solve (" + accuracy_clock_name(options.clock) + " ms)";
  char annulus[160];
  std::snprintf(annulus, sizeof annulus, "max |H - sqrt(r) sin(theta/2)| / sqrt(r) over %g <= r <= %g element lengths",
                options.r_min, options.r_max);
  chart.error_label = annulus;
  enum class Solver { cholmod, multigrid };
  for (Solver solver : {Solver::cholmod, Solver::multigrid}) {
    const std::string series = solver == Solver::cholmod ? "CHOLMOD" : "multigrid";
    for (int T : options.resolutions) {
      const CrackTipProblem problem = make_problem(T);
      double best_ms = std::numeric_limits<double>::infinity();
      kernels::TexelTile solution;
      int iterations = 0;
      for (int r = 0; r < std::max(1, options.repeat); ++r) {
        if (solver == Solver::cholmod) {
          const double start = accuracy_clock_ms(options.clock);
          HarmonicEnrichment h = harmonic_enrichment(problem.tile, problem.cut, problem.side_value);
          best_ms = std::min(best_ms, accuracy_clock_ms(options.clock) - start);
          solution = std::move(h.tile);
        } else {
          kernels::TexelTile tile = problem.tile;
          LaplaceMultigridOptions mg;
          mg.tolerance = options.multigrid_tolerance;
          mg.warm_start = false;
          const double start = accuracy_clock_ms(options.clock);
          set_cut_dirichlet(tile, problem.cut, problem.side_value);
          const LaplaceSolveStats stats = solve_laplace(tile, LaplaceSolver::multigrid, mg);
          best_ms = std::min(best_ms, accuracy_clock_ms(options.clock) - start);
          iterations = stats.iterations;
          solution = std::move(tile);
        }
      }
      const TipError e = tip_error(solution, problem.tip, options.r_min, options.r_max);
      int unknowns = 0;
      for (std::uint8_t f : solution.flags) unknowns += !(f & (kernels::dirichlet | kernels::inactive));
      AccuracyPoint p;
      p.series = series;
      p.label = "T=" + std::to_string(T);
      p.ms = best_ms;
      p.error = e.max;
      p.extra = {{"T", T}, {"rms_error", e.rms}, {"texels", e.texels}, {"unknowns", unknowns}};
      if (solver == Solver::multigrid) p.extra.push_back({"iterations", iterations});
      chart.points.push_back(p);
      if (progress) {
        char line[200];
        std::snprintf(line, sizeof line, "texture %-9s T=%-4d: %8.2f ms, max error %.3e, rms %.3e (%d unknowns)",
                      series.c_str(), T, p.ms, e.max, e.rms, unknowns);
        progress(line);
      }
    }
  }
  return chart;
}

}  // namespace dgtex
