#pragma once
// `dgtex bench render`: cut-boundary error (in texels) against triangles drawn for the
// renderer's cut methods (thesis §5.4.3, Fig. 5.10) on one synthetic cut state, with
// frame times.
//
// The state (render_bench_state): a flat plate [0, 3] x [0, 2] (z = 0) of 3 x 2 quad8
// elements of size 1 with two cuts, each piece moved rigidly or near rigidly so that the
// cut opens into a visible gap:
//  - a complete wavy cut x = 1.5 + 0.25 sin(1.3 pi y + 0.4) through the middle column,
//    H1 = -1 left of it, +1 right (exact), the sides pulled apart along x by 0.1;
//  - a partial straight cut in element [2,3] x [0,1] from the tip (2.35, 0.55) to the
//    right edge along (1, -0.3), H2 = angle around the tip / pi (jumps from -1 to +1
//    across the cut, continuous elsewhere) faded quadratically to 0 within 0.2 of the
//    element's shared edges, the sides opened by 0.05 across the cut.
// Displacement x = X + H1 d1 + H2 d2: nodes get u = H1(X) d1 + H2(X) d2; the two middle
// elements carry H1, the cut corner element H2, each with DOFs d_k on all its nodes.
// Viewed from straight above (render_bench_view), 1280 x 720 by default.
// Plain functions that return their results (nothing kept); rendering needs one thread per
// EGL context, so run one at a time. Times in ms, errors in texels, images in pixels.
#include <string>
#include <vector>

#include "dgtex/shell_renderer.h"
#include "dgtex/shell_state.h"

namespace dgtex {

constexpr double kRenderBenchTipRadius = 4.0;  // texels

struct RenderBenchOptions {
  int resolution = 64;  // texels per element side T (8..256); "per-texel" draws tessellation T
  int width = 1280, height = 720;
  std::vector<int> tessellations = {2, 4, 8, 16, 32};  // for each of the three cut methods
  int repeat = 5;  // timed renders per case (after one untimed warm-up); medians reported
  bool partial_cut = true;  // false: the complete cut only
};

struct RenderBenchCase {
  std::string method;  // "per-texel" (geometry shader at tessellation T), "geometry-shader",
                       // "drop-triangles", "kill-pixels"
  RenderSettings::CutMethod cut_method = RenderSettings::CutMethod::geometry_shader;
  int tessellation = 0;
  long long triangles_submitted = 0;  // tessellation triangles x elements
  long long triangles_drawn = 0;      // emitted by the geometry stage (GL_PRIMITIVES_GENERATED)
  // Largest cut-boundary error (dgtex/cut_boundary_error.h) away from the partial cut's
  // tip (outside kRenderBenchTipRadius texels of it), and its mean over the mismatched pixels.
  double error_texels = 0;
  double mean_error_texels = 0;
  long mismatched_pixels = 0;
  // The largest error including the tip: there H2 is continuous but steep, and the
  // tear criterion (|h_i - h_j| > cut_threshold with a sign change) opens a false tear
  // behind the tip about as long as a tessellation triangle (the truth: about a texel).
  double error_with_tip_texels = 0;
  double upload_ms = 0, draw_ms = 0, frame_ms = 0;  // medians; frame = upload + draw (incl. read-back)
};

struct RenderBenchResult {
  std::vector<RenderBenchCase> cases;  // per-texel first
  double texel_pixels = 0;             // projected size of one texel
  int width = 0, height = 0, resolution = 0;
  int elements = 0, enrichments = 0;
  bool partial_cut = true;
  std::string device;  // the EGL context's description
};

ShellState render_bench_state(int resolution, bool partial_cut = true);
RenderSettings render_bench_view(int width, int height);
// World length of one texel of render_bench_state(resolution) in pixels of render_bench_view.
double render_bench_texel_pixels(int resolution, int width, int height);

// Throws std::invalid_argument for options out of range (named in the message).
RenderBenchResult run_render_benchmark(const RenderBenchOptions& options, ShellRenderer& renderer);

}  // namespace dgtex
