#include "dgtex/render_benchmark.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>

#include "dgtex/cut_boundary_error.h"
#include "dgtex/deformed_shell.h"
#include "dgtex/mesh_generators.h"

namespace dgtex {

namespace {

constexpr double kPlateX = 3.0, kPlateY = 2.0;
constexpr double kCompleteGap = 0.1, kPartialOpening = 0.05;
constexpr double kTipX = 2.35, kTipY = 0.55;
constexpr double kFadeWidth = 0.2;  // H2 fades out quadratically over this distance from shared edges
constexpr double kFovDeg = 30;

double wavy_cut_x(double y) { return 1.5 + 0.25 * std::sin(1.3 * M_PI * y + 0.4); }

// -1 left of the complete cut, +1 right of it.
double complete_cut_side(double x, double y) { return x < wavy_cut_x(y) ? -1.0 : 1.0; }

// Direction of the partial cut from its tip and the normal on its left.
void partial_cut_frame(double dir[2], double normal[2]) {
  const double length = std::hypot(1.0, -0.3);
  dir[0] = 1.0 / length;
  dir[1] = -0.3 / length;
  normal[0] = -dir[1];
  normal[1] = dir[0];
}

// Angle around the tip / pi, measured so that the jump (-1 | +1) lies on the cut (-1 on
// the side of `normal`), times a fade to zero on the edges element [2,3] x [0,1] shares
// with its neighbours (so that no other element needs H2 and per-element texel sampling
// leaves no cracks there); 0 outside that element.
double partial_cut_value(double x, double y) {
  const double edge_distance = std::min({x - 2.0, y, 1.0 - y});
  if (edge_distance <= 0) return 0.0;
  const double fade = std::min(1.0, edge_distance / kFadeWidth);
  double dir[2], normal[2];
  partial_cut_frame(dir, normal);
  const double u = (x - kTipX) * dir[0] + (y - kTipY) * dir[1];
  const double v = (x - kTipX) * normal[0] + (y - kTipY) * normal[1];
  return fade * fade * std::atan2(-v, -u) / M_PI;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace

ShellState render_bench_state(int resolution, bool partial_cut) {
  if (resolution < 8 || resolution > 4096)
    throw std::invalid_argument("render benchmark resolution " + std::to_string(resolution) + " (valid: 8..4096)");
  ShellState state;
  state.mesh = make_rectangle(kPlateX, kPlateY, 3, 2, ElementType::quad8);
  const Mesh& mesh = state.mesh;
  double dir[2], normal[2];
  partial_cut_frame(dir, normal);
  // The side on `normal` (H2 = -1) moves along +normal: d2 = -opening / 2 * normal.
  const double d1[3] = {0.5 * kCompleteGap, 0, 0};
  const double d2[3] = {-0.5 * kPartialOpening * normal[0], -0.5 * kPartialOpening * normal[1], 0};
  state.displacement.assign(mesh.positions.size(), 0.0);
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    const double x = mesh.positions[3 * n], y = mesh.positions[3 * n + 1];
    const double h1 = complete_cut_side(x, y), h2 = partial_cut ? partial_cut_value(x, y) : 0.0;
    for (int d = 0; d < 3; ++d) state.displacement[3 * n + d] = h1 * d1[d] + h2 * d2[d];
  }
  const int npe = mesh.nodes_per_element();
  auto rest_point = [&](int e, double xi1, double xi2, double& x, double& y) {
    kernels::ShapeValues sv;
    kernels::evaluate_shape(mesh.type, xi1, xi2, sv);
    const int* nodes = mesh.element_nodes(e);
    x = y = 0;
    for (int a = 0; a < npe; ++a) {
      x += sv.N[a] * mesh.positions[3 * nodes[a]];
      y += sv.N[a] * mesh.positions[3 * nodes[a] + 1];
    }
  };
  auto enrich = [&](int e, const std::function<double(double, double)>& H, const double* dofs) {
    ElementEnrichment en;
    en.element = e;
    en.resolution = resolution;
    en.values.resize(static_cast<size_t>(resolution) * resolution);
    for (int j = 0; j < resolution; ++j)
      for (int i = 0; i < resolution; ++i) {
        double x, y;
        rest_point(e, -1.0 + (2.0 * i + 1.0) / resolution, -1.0 + (2.0 * j + 1.0) / resolution, x, y);
        en.values[static_cast<size_t>(j) * resolution + i] = static_cast<float>(H(x, y));
      }
    const int* nodes = mesh.element_nodes(e);
    for (int a = 0; a < npe; ++a) {
      en.node_values.push_back(static_cast<float>(H(mesh.positions[3 * nodes[a]], mesh.positions[3 * nodes[a] + 1])));
      en.dofs.insert(en.dofs.end(), dofs, dofs + 3);
    }
    state.enrichments.push_back(std::move(en));
  };
  for (int e = 0; e < mesh.num_elements(); ++e) {
    double cx, cy;
    rest_point(e, 0, 0, cx, cy);
    if (cx > 1 && cx < 2) enrich(e, complete_cut_side, d1);
    if (partial_cut && cx > 2 && cy < 1) enrich(e, partial_cut_value, d2);
  }
  return state;
}

RenderSettings render_bench_view(int width, int height) {
  RenderSettings s;
  s.width = width;
  s.height = height;
  s.fov_deg = kFovDeg;
  const double half_x = 0.5 * kPlateX + 0.15, half_y = 0.5 * kPlateY + 0.15;  // room for the moved pieces
  const double tan_half = std::tan(0.5 * kFovDeg * M_PI / 180.0);
  const double distance = std::max(half_y, half_x * height / width) / tan_half;
  const double target[3] = {0.5 * kPlateX, 0.5 * kPlateY, 0};
  for (int d = 0; d < 3; ++d) {
    s.camera_target[d] = target[d];
    s.camera_position[d] = target[d];
  }
  s.camera_position[2] = distance;
  s.camera_up[0] = 0;
  s.camera_up[1] = 1;
  s.camera_up[2] = 0;
  return s;
}

double render_bench_texel_pixels(int resolution, int width, int height) {
  const RenderSettings s = render_bench_view(width, height);
  const double tan_half = std::tan(0.5 * s.fov_deg * M_PI / 180.0);
  const double pixels_per_unit = 0.5 * height / (s.camera_position[2] * tan_half);
  return pixels_per_unit / resolution;  // elements are 1 x 1
}

RenderBenchResult run_render_benchmark(const RenderBenchOptions& options, ShellRenderer& renderer) {
  if (options.resolution < 8 || options.resolution > 256)
    throw std::invalid_argument("--resolution " + std::to_string(options.resolution) + " (valid: 8..256)");
  if (options.width < 16 || options.height < 16 || options.width > 8192 || options.height > 8192)
    throw std::invalid_argument("image size " + std::to_string(options.width) + " x " + std::to_string(options.height) +
                                " (valid: 16..8192 each)");
  if (options.repeat < 1) throw std::invalid_argument("--repeat " + std::to_string(options.repeat) + " (valid: >= 1)");
  for (int t : options.tessellations)
    if (t < 1 || t > 256)
      throw std::invalid_argument("tessellation " + std::to_string(t) + " (valid: 1..256)");

  const ShellState state = render_bench_state(options.resolution, options.partial_cut);
  RenderBenchResult result;
  result.width = options.width;
  result.height = options.height;
  result.resolution = options.resolution;
  result.partial_cut = options.partial_cut;
  result.elements = state.mesh.num_elements();
  result.enrichments = static_cast<int>(state.enrichments.size());
  result.texel_pixels = render_bench_texel_pixels(options.resolution, options.width, options.height);
  result.device = renderer.context().description();
  const RenderSettings view = render_bench_view(options.width, options.height);
  const Camera camera = make_camera(state, view);
  const std::vector<std::uint8_t> exact = exact_cut_coverage(state, camera);
  // Pixels near the partial cut's tip (it stays in place: H2 has mean 0 around it).
  std::vector<std::uint8_t> near_tip(exact.size(), 0);
  {
    const double tip[3] = {kTipX, kTipY, 0};
    double tx, ty;
    camera.project(tip, tx, ty);
    const double radius = kRenderBenchTipRadius * result.texel_pixels;
    for (int y = 0; y < view.height; ++y)
      for (int x = 0; x < view.width; ++x)
        near_tip[static_cast<size_t>(y) * view.width + x] = std::hypot(x + 0.5 - tx, y + 0.5 - ty) <= radius;
  }

  auto run_case = [&](const std::string& name, RenderSettings::CutMethod method, int tessellation) {
    RenderSettings s = view;
    s.cut_method = method;
    s.tessellation = tessellation;
    Image image = renderer.render(state, s);  // warm-up: compiles the program, builds the tessellation
    std::vector<double> upload, draw, frame;
    for (int r = 0; r < options.repeat; ++r) {
      image = renderer.render(state, s);
      upload.push_back(renderer.last_upload_ms());
      draw.push_back(renderer.last_draw_ms());
      frame.push_back(renderer.last_upload_ms() + renderer.last_setup_ms() + renderer.last_draw_ms());
    }
    const std::vector<std::uint8_t> rendered = image_coverage(image, s.background);
    const CoverageError error = coverage_error(rendered, exact, s.width, s.height, &near_tip);
    const CoverageError with_tip = coverage_error(rendered, exact, s.width, s.height);
    RenderBenchCase c;
    c.method = name;
    c.cut_method = method;
    c.tessellation = tessellation;
    c.triangles_submitted = renderer.last_triangles_submitted();
    c.triangles_drawn = renderer.last_triangles_drawn();
    c.error_texels = error.max_pixels / result.texel_pixels;
    c.mean_error_texels = error.mean_pixels / result.texel_pixels;
    c.mismatched_pixels = error.mismatched;
    c.error_with_tip_texels = with_tip.max_pixels / result.texel_pixels;
    c.upload_ms = median(upload);
    c.draw_ms = median(draw);
    c.frame_ms = median(frame);
    result.cases.push_back(c);
  };
  run_case("per-texel", RenderSettings::CutMethod::geometry_shader, options.resolution);
  for (auto method : {RenderSettings::CutMethod::geometry_shader, RenderSettings::CutMethod::drop_triangles,
                      RenderSettings::CutMethod::kill_pixels})
    for (int t : options.tessellations) run_case(to_string(method), method, t);
  return result;
}

}  // namespace dgtex
