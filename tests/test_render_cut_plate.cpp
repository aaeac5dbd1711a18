// The cut-shell renderer in a real EGL context (llvmpipe without a GPU) against plates
// whose cut geometry is known exactly (tests/render_fixtures.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "dgtex/deformed_shell.h"
#include "dgtex/png_io.h"
#include "dgtex/shell_renderer.h"
#include "render_fixtures.h"

namespace dgtex {
namespace {

// One context and renderer for the whole executable (context creation costs ~0.1 s).
ShellRenderer& renderer() {
  static ShellRenderer instance;
  return instance;
}

// With DGTEX_RENDER_TEST_DUMP=DIR the test images are written there for inspection.
void dump(const Image& image, const std::string& name) {
  if (const char* dir = std::getenv("DGTEX_RENDER_TEST_DUMP")) write_png(std::string(dir) + "/" + name + ".png", image);
}

// Pixel-centre ray of the top view hits z = 0 at (x, y) (camera looks straight down).
void unproject_top_view(const RenderSettings& s, double px, double py, double& x, double& y) {
  const double distance = s.camera_position[2];
  const double half_h = distance * std::tan(0.5 * s.fov_deg * M_PI / 180.0);
  const double half_w = half_h * double(s.width) / s.height;
  x = s.camera_target[0] + ((px + 0.5) / s.width * 2 - 1) * half_w;
  y = s.camera_target[1] + (1 - (py + 0.5) / s.height * 2) * half_h;
}

// Boundary error of a straight cut: per image row through the middle of the plate, the
// longest background run near the cut is the rendered gap; its ends are compared with
// the projected ends of the true gap (left piece ends at cut_x - gap, right starts at
// cut_x). Returns the largest error in pixels over the rows (infinity if a row has no gap).
double straight_cut_boundary_error(const Image& image, const RenderSettings& s, const test::CutPlate& plate,
                                   double& texel_pixels) {
  const Camera camera = make_camera(plate.state, s);
  const double cut_x = double(plate.cut_column[0]) / plate.resolution;
  double worst = 0;
  for (double y = 0.1; y <= 0.9; y += 0.01) {
    const double left_end[3] = {cut_x - plate.gap, y, 0}, right_start[3] = {cut_x, y, 0};
    const double one_texel[3] = {cut_x + plate.texel_size, y, 0};
    double lx, ly, rx, ry, tx, ty;
    camera.project(left_end, lx, ly);
    camera.project(right_start, rx, ry);
    camera.project(one_texel, tx, ty);
    texel_pixels = tx - rx;
    const int row = static_cast<int>(std::floor(ly));
    const int from = std::max(0, static_cast<int>(lx - 4 * texel_pixels));
    const int to = std::min(image.width, static_cast<int>(rx + 4 * texel_pixels));
    int best_start = -1, best_length = 0;
    for (int x = from; x < to;) {
      if (!test::is_background(image, x, row, s.background)) {
        ++x;
        continue;
      }
      int end = x;
      while (end < to && test::is_background(image, end, row, s.background)) ++end;
      if (end - x > best_length) {
        best_length = end - x;
        best_start = x;
      }
      x = end;
    }
    if (best_length == 0) return std::numeric_limits<double>::infinity();
    // Pixel edges of the run: [best_start, best_start + best_length].
    worst = std::max({worst, std::abs(best_start - lx), std::abs(best_start + best_length - rx)});
  }
  return worst;
}

TEST(RenderCutPlate, CompleteCutRendersAsTwoComponentsWithTheGap) {
  const auto plate = test::straight_cut_plate();
  const RenderSettings s = test::top_view();
  const Image image = renderer().render(plate.state, s);
  dump(image, "straight_cut_geometry_shader");
  EXPECT_EQ(test::count_components(image, s.background), 2);
  // The gap (0.2 world units) is about 19 pixels wide in this view; require at least 15.
  const Camera camera = make_camera(plate.state, s);
  const double a[3] = {0.5625 - plate.gap, 0.5, 0}, b[3] = {0.5625, 0.5, 0};
  double ax, ay, bx, by;
  camera.project(a, ax, ay);
  camera.project(b, bx, by);
  ASSERT_GT(bx - ax, 15.0);
  const int row = static_cast<int>(ay);
  for (int x = static_cast<int>(std::ceil(ax + 1)); x < static_cast<int>(bx - 1); ++x)
    EXPECT_TRUE(test::is_background(image, x, row, s.background)) << "pixel " << x << " inside the gap is covered";
}

TEST(RenderCutPlate, CutBoundaryLiesWithinOneProjectedTexel) {
  const auto plate = test::straight_cut_plate();
  const RenderSettings s = test::top_view();
  const Image image = renderer().render(plate.state, s);
  double texel_pixels = 0;
  const double error = straight_cut_boundary_error(image, s, plate, texel_pixels);
  ASSERT_GT(texel_pixels, 3.0);  // the test is meaningful only if a texel spans pixels
  EXPECT_LE(error, texel_pixels) << "texel = " << texel_pixels << " px";
}

// Fig. 5.10 on the straight cut x = 9/16 with tessellation 4 (triangle columns of 4
// texels): dropping cut triangles loses the column xi1 in [0, 0.5], so the right piece
// starts 3 texels late; killing pixels within one texel of the cut leaves the column's
// stretched triangles in place and opens the gap where the killed texels land, which here
// puts the left end of the gap 1 texel early. The geometry shader stays within a texel.
TEST(RenderCutPlate, SimplerCutMethodsHaveLargerBoundaryErrors) {
  const auto plate = test::straight_cut_plate();
  double errors[3], texel_pixels = 0;
  for (auto method : {RenderSettings::CutMethod::geometry_shader, RenderSettings::CutMethod::drop_triangles,
                      RenderSettings::CutMethod::kill_pixels}) {
    RenderSettings s = test::top_view();
    s.cut_method = method;
    const Image image = renderer().render(plate.state, s);
    dump(image, std::string("straight_cut_") + to_string(method));
    errors[static_cast<int>(method)] = straight_cut_boundary_error(image, s, plate, texel_pixels);
  }
  std::printf("boundary errors (px): geometry shader %.2f, drop triangles %.2f, kill pixels %.2f; texel %.2f px\n",
              errors[0], errors[1], errors[2], texel_pixels);
  SCOPED_TRACE("boundary errors in pixels: geometry shader " + std::to_string(errors[0]) + ", drop triangles " +
               std::to_string(errors[1]) + ", kill pixels " + std::to_string(errors[2]) + "; texel " +
               std::to_string(texel_pixels));
  EXPECT_LE(errors[0], texel_pixels);
  EXPECT_NEAR(errors[1], 3 * texel_pixels, 1.5);
  EXPECT_NEAR(errors[2], 1 * texel_pixels, 1.5);
  EXPECT_LT(errors[0], errors[1]);
  EXPECT_LT(errors[0], errors[2]);
  EXPECT_LT(errors[2], errors[1]);
}

// Rasterised oracle for a staircase cut: every pixel whose centre lies more than 1.5
// pixels from the boundary of the exact deformed plate must be covered exactly when the
// plate covers it. In particular no fragment of one side appears beyond the cut (the
// extrapolated part of each copy would land in the gap).
TEST(RenderCutPlate, StaircaseCutMatchesTheExactCoverage) {
  const auto plate = test::staircase_cut_plate();
  for (int tessellation : {1, 4, 8}) {
    RenderSettings s = test::top_view();
    s.tessellation = tessellation;
    s.wireframe = false;
    const Image image = renderer().render(plate.state, s);
    dump(image, "staircase_tessellation_" + std::to_string(tessellation));
    double x0, y0, x1, y1;
    unproject_top_view(s, 0, 0, x0, y0);
    unproject_top_view(s, 1, 1, x1, y1);
    const double pixel = std::abs(x1 - x0);
    {  // the unprojection agrees with the renderer's camera
      const Camera camera = make_camera(plate.state, s);
      const double p[3] = {x0, y0, 0};
      double px, py;
      camera.project(p, px, py);
      ASSERT_NEAR(px, 0.5, 1e-6);
      ASSERT_NEAR(py, 0.5, 1e-6);
    }
    int checked = 0, wrong = 0;
    for (int py = 0; py < s.height; ++py)
      for (int px = 0; px < s.width; ++px) {
        double x, y;
        unproject_top_view(s, px, py, x, y);
        const bool inside = plate.covers(x, y);
        bool clear = true;
        for (int k = 0; k < 16 && clear; ++k) {
          const double angle = 2 * M_PI * k / 16;
          clear = plate.covers(x + 1.5 * pixel * std::cos(angle), y + 1.5 * pixel * std::sin(angle)) == inside;
        }
        if (!clear) continue;
        ++checked;
        if (test::is_background(image, px, py, s.background) == inside) ++wrong;
      }
    EXPECT_GT(checked, s.width * s.height * 9 / 10);
    EXPECT_EQ(wrong, 0) << "tessellation " << tessellation;
    EXPECT_EQ(test::count_components(image, s.background), 2) << "tessellation " << tessellation;
  }
}

// The vertex stage's shape functions (GLSL twin) against the CPU evaluation: a plate
// warped by a quadratic displacement, quad8 and tri6. Points of the surface sampled on
// the CPU must project onto covered pixels (away from the silhouette), and no pixel
// farther than 2 pixels from every sample may be covered.
TEST(RenderCutPlate, DeformedGeometryMatchesTheCpuEvaluation) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    ShellState state;
    state.mesh = test::rectangle_mesh(type, 2, 2, 1.6, 1.0);
    for (int n = 0; n < state.mesh.num_nodes(); ++n) {
      const double x = state.mesh.positions[3 * n], y = state.mesh.positions[3 * n + 1];
      state.displacement.insert(state.displacement.end(), {0.25 * y * y, 0.2 * x * x - 0.1 * x * y, 0.0});
    }
    RenderSettings s = test::top_view();
    s.tessellation = 8;
    const Image image = renderer().render(state, s);
    dump(image, std::string("warped_") + (type == ElementType::quad8 ? "quad8" : "tri6"));
    const Camera camera = make_camera(state, s);
    const DeformedShell shell(state);
    std::vector<char> near(static_cast<size_t>(s.width) * s.height, 0);
    int inside_checked = 0, inside_wrong = 0;
    const int samples = 160;
    for (int e = 0; e < state.mesh.num_elements(); ++e)
      for (int j = 0; j <= samples; ++j)
        for (int i = 0; i <= samples; ++i) {
          double u = double(i) / samples, v = double(j) / samples;
          if (type == ElementType::tri6 && u + v > 1) continue;
          const double xi1 = type == ElementType::quad8 ? 2 * u - 1 : u, xi2 = type == ElementType::quad8 ? 2 * v - 1 : v;
          double x[3], px, py;
          shell.position(e, xi1, xi2, x);
          camera.project(x, px, py);
          for (int dy = -2; dy <= 2; ++dy)
            for (int dx = -2; dx <= 2; ++dx) {
              const int qx = static_cast<int>(std::floor(px)) + dx, qy = static_cast<int>(std::floor(py)) + dy;
              if (qx >= 0 && qy >= 0 && qx < s.width && qy < s.height) near[qy * s.width + qx] = 1;
            }
          // Away from the plate's outer boundary (rest coordinates X = 0, 1.6, Y = 0, 1)
          // the sample's pixel is covered.
          kernels::ShapeValues sv;
          kernels::evaluate_shape(type, xi1, xi2, sv);
          double X = 0, Y = 0;
          const int* nodes = state.mesh.element_nodes(e);
          for (int a = 0; a < state.mesh.nodes_per_element(); ++a) {
            X += sv.N[a] * state.mesh.positions[3 * nodes[a]];
            Y += sv.N[a] * state.mesh.positions[3 * nodes[a] + 1];
          }
          const double margin = std::min({X, 1.6 - X, Y, 1.0 - Y});
          if (margin < 0.05) continue;  // 0.05 world units is about 5 pixels here
          ++inside_checked;
          if (test::is_background(image, static_cast<int>(px), static_cast<int>(py), s.background)) ++inside_wrong;
        }
    int outside_wrong = 0;
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x)
        if (!near[y * s.width + x] && !test::is_background(image, x, y, s.background)) ++outside_wrong;
    EXPECT_GT(inside_checked, 10000);
    EXPECT_EQ(inside_wrong, 0) << (type == ElementType::quad8 ? "quad8" : "tri6");
    EXPECT_EQ(outside_wrong, 0) << (type == ElementType::quad8 ? "quad8" : "tri6");
  }
}

TEST(RenderCutPlate, UncutPlateIsOneComponentAndSmoothShadingWorks) {
  auto plate = test::straight_cut_plate();
  plate.state.enrichments.clear();
  plate.state.displacement.assign(plate.state.displacement.size(), 0.0);
  RenderSettings s = test::top_view();
  s.shading = RenderSettings::Shading::smooth;
  const Image image = renderer().render(plate.state, s);
  EXPECT_EQ(test::count_components(image, s.background), 1);
  // A flat plate seen head-on under a headlight: smooth shading is one uniform colour
  // away from the silhouette.
  const auto* centre = image.pixel(s.width / 2, s.height / 2);
  const auto* other = image.pixel(s.width / 2 + 40, s.height / 2 + 10);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(centre[c], other[c], 2);
}

TEST(RenderCutPlate, FlatShadingColoursElementsDistinctly) {
  auto plate = test::straight_cut_plate();
  plate.state.enrichments.clear();
  plate.state.displacement.assign(plate.state.displacement.size(), 0.0);
  const RenderSettings s = test::top_view();
  const Image image = renderer().render(plate.state, s);
  const Camera camera = make_camera(plate.state, s);
  const double e0[3] = {0.5, 0.5, 0}, e1[3] = {1.5, 0.5, 0};
  double x0, y0, x1, y1;
  camera.project(e0, x0, y0);
  camera.project(e1, x1, y1);
  const auto* p0 = image.pixel(static_cast<int>(x0), static_cast<int>(y0));
  const auto* p1 = image.pixel(static_cast<int>(x1), static_cast<int>(y1));
  int difference = 0;
  for (int c = 0; c < 3; ++c) difference += std::abs(p0[c] - p1[c]);
  EXPECT_GT(difference, 30);
}

TEST(RenderCutPlate, EmptyStateRendersTheBackground) {
  RenderSettings s = test::top_view(16, 8);
  s.background[0] = 0.2f;
  const Image image = renderer().render(ShellState{}, s);
  EXPECT_EQ(test::count_components(image, s.background), 0);
  EXPECT_EQ(image.pixel(3, 3)[0], 51);
}

TEST(RenderCutPlate, RejectsTooManyEnrichmentsAndBadSettings) {
  auto plate = test::straight_cut_plate();
  for (int k = 0; k < kMaxEnrichmentsPerElement; ++k) plate.state.enrichments.push_back(plate.state.enrichments[0]);
  EXPECT_THROW(renderer().render(plate.state, test::top_view()), std::invalid_argument);
  auto ok = test::straight_cut_plate();
  RenderSettings s = test::top_view();
  s.width = 0;
  EXPECT_THROW(renderer().render(ok.state, s), std::invalid_argument);
  s = test::top_view();
  s.tessellation = 0;
  EXPECT_THROW(renderer().render(ok.state, s), std::invalid_argument);
  // Drawn before (helper audit, session 71): a NaN background, a zero up, enum values
  // outside their types.
  const std::vector<std::function<void(RenderSettings&)>> bad = {
      [](RenderSettings& r) { r.background[1] = std::nanf(""); },
      [](RenderSettings& r) { r.background[2] = 2.0f; },
      [](RenderSettings& r) { r.camera_up[0] = r.camera_up[1] = r.camera_up[2] = 0; },
      [](RenderSettings& r) { r.shading = static_cast<RenderSettings::Shading>(9); },
      [](RenderSettings& r) { r.cut_method = static_cast<RenderSettings::CutMethod>(9); }};
  for (size_t k = 0; k < bad.size(); ++k) {
    s = test::top_view();
    bad[k](s);
    EXPECT_THROW(renderer().render(ok.state, s), std::invalid_argument) << k;
  }
  // Coordinates past the shaders' 32-bit floats drew a blank image (fuzzing, session 71).
  auto far = test::straight_cut_plate();
  for (double& x : far.state.mesh.positions) x *= 1e35;
  try {
    renderer().render(far.state, test::top_view());
    ADD_FAILURE() << "drew a shell of 1e35";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("beyond what the renderer's 32-bit floats draw"), std::string::npos) << e.what();
  }
}

// One element [0,1]^2 with complete straight cuts k (vertical ones at x = c, horizontal
// ones at y = c), enrichment H_k = -1 below c, +1 above. With q_k^a = alpha_k for all
// nodes and u^a = sum_k H_k(xi^a) alpha_k, each piece moves rigidly by sum_k H_k alpha_k.
ShellState multiply_cut_square(const std::vector<std::pair<int, double>>& cuts, double pull, int T = 16) {
  ShellState state;
  state.mesh = test::rectangle_mesh(ElementType::quad8, 1, 1, 1.0, 1.0);
  state.displacement.assign(state.mesh.positions.size(), 0.0);
  const int* nodes = state.mesh.element_nodes(0);
  for (const auto& [axis, c] : cuts) {
    ElementEnrichment e;
    e.element = 0;
    e.resolution = T;
    for (int j = 0; j < T; ++j)
      for (int i = 0; i < T; ++i) e.values.push_back(((axis == 0 ? i : j) + 0.5) / T < c ? -1.0f : 1.0f);
    for (int a = 0; a < 8; ++a) {
      double xi[2];
      kernels::node_parametric_position(ElementType::quad8, a, xi);
      const float h = 0.5 * (xi[axis] + 1) < c ? -1.0f : 1.0f;
      e.node_values.push_back(h);
      for (int d = 0; d < 3; ++d) e.dofs.push_back(d == axis ? pull : 0.0);
      state.displacement[3 * nodes[a] + axis] += h * pull;
    }
    state.enrichments.push_back(e);
  }
  return state;
}

TEST(RenderCutPlate, SeveralEnrichmentsPerElementSplitIntoPieces) {
  RenderSettings s = test::top_view();
  s.camera_target[0] = s.camera_position[0] = 0.5;
  s.camera_position[2] = 6;
  {  // two cuts through the centre: four quadrants moved by (+-0.15, +-0.15)
    const ShellState state = multiply_cut_square({{0, 0.5}, {1, 0.5}}, 0.15);
    const Image image = renderer().render(state, s);
    dump(image, "two_cuts");
    EXPECT_EQ(test::count_components(image, s.background), 4);
    const Camera camera = make_camera(state, s);
    for (int v : {-1, 1})
      for (int w : {-1, 1}) {
        // Quadrant centres are covered; the gap between neighbours is not.
        const double centre[3] = {0.5 + 0.4 * v, 0.5 + 0.4 * w, 0}, gap[3] = {0.5, 0.5 + 0.4 * w, 0};
        double x, y;
        camera.project(centre, x, y);
        EXPECT_FALSE(test::is_background(image, static_cast<int>(x), static_cast<int>(y), s.background));
        camera.project(gap, x, y);
        EXPECT_TRUE(test::is_background(image, static_cast<int>(x), static_cast<int>(y), s.background));
      }
  }
  {  // 4 cuts at 1/4 and 3/4 in both directions: 9 pieces
    const ShellState state = multiply_cut_square({{0, 0.25}, {0, 0.75}, {1, 0.25}, {1, 0.75}}, 0.08);
    ASSERT_EQ(static_cast<int>(state.enrichments.size()), 4);
    const Image image = renderer().render(state, s);
    dump(image, "four_cuts");
    EXPECT_EQ(test::count_components(image, s.background), 9);
  }
}

}  // namespace
}  // namespace dgtex
