// The renderer with many enrichment functions on one element (more than the old limit of
// 4): a quad8 strip cut completely by 10 parallel cuts into 11 pieces that move apart
// and alternately up and down, with geometry known exactly. Images of states with at most
// 4 enrichments per element are covered by test_render_reference / test_render_cut_plate.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "dgtex/png_io.h"
#include "dgtex/shell_renderer.h"
#include "render_fixtures.h"

namespace dgtex {
namespace {

ShellRenderer& renderer() {
  static ShellRenderer instance;
  return instance;
}

// With DGTEX_RENDER_TEST_DUMP=DIR the test images are written there for inspection.
void dump(const Image& image, const std::string& name) {
  if (const char* dir = std::getenv("DGTEX_RENDER_TEST_DUMP")) write_png(std::string(dir) + "/" + name + ".png", image);
}

// One quad8 element [0, 2.2] x [0, 1] (texel 0.05 for T = 44) with cuts k = 1..10 at
// x = 0.2 k along texel edges: H_k = -1 left of cut k, +1 right of it. With
// q_k^a = (gap/2, 0, lift (-1)^k) for all nodes and u^a = sum_k H_k(xi^a) q_k + lift e_z,
// piece p (between cuts p and p + 1) moves rigidly by (gap (p - 5), 0, lift (-1)^p).
struct SlicedStrip {
  static constexpr int kCuts = 10, kResolution = 44;
  static constexpr double kLength = 2.2, kSpacing = 0.2;
  double gap, lift;
  ShellState state;

  SlicedStrip(double gap_, double lift_) : gap(gap_), lift(lift_) {
    state.mesh = test::rectangle_mesh(ElementType::quad8, 1, 1, kLength, 1.0);
    state.displacement.assign(state.mesh.positions.size(), 0.0);
    const int* nodes = state.mesh.element_nodes(0);
    for (int a = 0; a < 8; ++a) state.displacement[3 * nodes[a] + 2] = lift;
    for (int k = 1; k <= kCuts; ++k) {
      const int cut_texel = static_cast<int>(std::lround(k * kSpacing / kLength * kResolution));
      const double q[3] = {gap / 2, 0, k % 2 ? -lift : lift};
      ElementEnrichment e;
      e.element = 0;
      e.resolution = kResolution;
      for (int j = 0; j < kResolution; ++j)
        for (int i = 0; i < kResolution; ++i) e.values.push_back(i < cut_texel ? -1.0f : 1.0f);
      for (int a = 0; a < 8; ++a) {
        const double x = state.mesh.positions[3 * nodes[a]];
        const float h = x < k * kSpacing ? -1.0f : 1.0f;
        e.node_values.push_back(h);
        for (int d = 0; d < 3; ++d) {
          e.dofs.push_back(q[d]);
          state.displacement[3 * nodes[a] + d] += h * q[d];
        }
      }
      state.enrichments.push_back(e);
    }
  }
  // Deformed position of rest point (x, y) of piece p.
  void deformed(int p, double x, double y, double out[3]) const {
    out[0] = x + gap * (p - 5);
    out[1] = y;
    out[2] = p % 2 ? -lift : lift;
  }
  double piece_centre_x(int p) const { return (p + 0.5) * kSpacing; }
};

RenderSettings top_view(const SlicedStrip& strip) {
  RenderSettings s;
  s.width = 512;
  s.height = 256;
  s.camera_position[0] = s.camera_target[0] = 0.5 * SlicedStrip::kLength;
  s.camera_position[1] = s.camera_target[1] = 0.5;
  s.camera_position[2] = 5.0;
  s.camera_up[0] = 0;
  s.camera_up[1] = 1;
  s.camera_up[2] = 0;
  s.fov_deg = 30;
  (void)strip;
  return s;
}

// Runs of non-background pixels along image row y.
int runs_along_row(const Image& image, int y, const float background[3]) {
  int runs = 0;
  bool inside = false;
  for (int x = 0; x < image.width; ++x) {
    const bool covered = !test::is_background(image, x, y, background);
    if (covered && !inside) ++runs;
    inside = covered;
  }
  return runs;
}

TEST(RenderManyEnrichments, TenParallelCutsGiveElevenPiecesWithGaps) {
  const SlicedStrip strip(0.08, 0.05);
  ASSERT_EQ(static_cast<int>(strip.state.enrichments.size()), 10);
  // Tessellation 4: triangles crossed by up to 3 cuts (8 copies each); 16: by one.
  for (int tessellation : {4, 16}) {
    SCOPED_TRACE("tessellation " + std::to_string(tessellation));
    RenderSettings s = top_view(strip);
    s.tessellation = tessellation;
    const Image image = renderer().render(strip.state, s);
    dump(image, "ten_cuts_t" + std::to_string(tessellation));
    const Camera camera = make_camera(strip.state, s);
    for (double y : {0.2, 0.5, 0.8}) {
      double p[3], px, py;
      strip.deformed(5, strip.piece_centre_x(5), y, p);
      camera.project(p, px, py);
      EXPECT_EQ(runs_along_row(image, static_cast<int>(py), s.background), 11) << "scan line y = " << y;
    }
    EXPECT_EQ(test::count_components(image, s.background), 11);
    for (int piece = 0; piece <= SlicedStrip::kCuts; ++piece) {
      double p[3], px, py;
      strip.deformed(piece, strip.piece_centre_x(piece), 0.5, p);
      camera.project(p, px, py);
      EXPECT_FALSE(test::is_background(image, static_cast<int>(px), static_cast<int>(py), s.background))
          << "piece " << piece;
    }
    // The gap at cut k spans x in [0.2 k + gap (k - 6), 0.2 k + gap (k - 5)] (between the
    // pieces k - 1 and k, one at +lift, one at -lift): its centre is background, and is
    // at least 3 pixels wide, so the check means something.
    for (int k = 1; k <= SlicedStrip::kCuts; ++k) {
      const double x = k * SlicedStrip::kSpacing + strip.gap * (k - 5.5);
      const double centre[3] = {x, 0.5, 0}, left[3] = {x - strip.gap / 2, 0.5, 0}, right[3] = {x + strip.gap / 2, 0.5, 0};
      double px, py, lx, rx, unused;
      camera.project(centre, px, py);
      camera.project(left, lx, unused);
      camera.project(right, rx, unused);
      ASSERT_GT(rx - lx, 3.0);
      EXPECT_TRUE(test::is_background(image, static_cast<int>(px), static_cast<int>(py), s.background)) << "cut " << k;
    }
  }
}

// An oblique view from -y and above: a piece's far edge (y = 1) lands where its own
// height puts it, so the pieces alternate visibly up and down.
TEST(RenderManyEnrichments, PiecesAlternateUpAndDown) {
  const SlicedStrip strip(0.08, 0.1);
  RenderSettings s = top_view(strip);
  s.camera_position[1] = -2.5;
  s.camera_position[2] = 3.0;
  s.camera_up[1] = 0;
  s.camera_up[2] = 1;
  s.tessellation = 8;
  const Image image = renderer().render(strip.state, s);
  dump(image, "ten_cuts_oblique");
  const Camera camera = make_camera(strip.state, s);
  for (int piece = 0; piece <= SlicedStrip::kCuts; ++piece) {
    double up[3], down[3], ux, uy, dx, dy;
    strip.deformed(piece, strip.piece_centre_x(piece), 1.0, up);
    up[2] = strip.lift;
    strip.deformed(piece, strip.piece_centre_x(piece), 1.0, down);
    down[2] = -strip.lift;
    camera.project(up, ux, uy);
    camera.project(down, dx, dy);
    ASSERT_GT(dy - uy, 6.0) << "the two heights must be distinguishable";
    // First covered pixel from the top of the image in the piece's centre column.
    const int column = static_cast<int>(0.5 * (ux + dx));
    int top = -1;
    for (int y = 0; y < image.height && top < 0; ++y)
      if (!test::is_background(image, column, y, s.background)) top = y;
    const double expected = piece % 2 ? dy : uy;
    EXPECT_NEAR(top + 0.5, expected, 1.5) << "piece " << piece;
  }
}

// drop-triangles and kill-pixels also take many enrichments; the cut positions stay open.
TEST(RenderManyEnrichments, OtherCutMethodsLeaveTheCutsOpen) {
  const SlicedStrip strip(0.08, 0.05);
  for (auto method : {RenderSettings::CutMethod::drop_triangles, RenderSettings::CutMethod::kill_pixels}) {
    SCOPED_TRACE(to_string(method));
    RenderSettings s = top_view(strip);
    s.tessellation = 16;
    s.cut_method = method;
    const Image image = renderer().render(strip.state, s);
    dump(image, std::string("ten_cuts_") + to_string(method));
    const Camera camera = make_camera(strip.state, s);
    for (int k = 1; k <= SlicedStrip::kCuts; ++k) {
      const double centre[3] = {k * SlicedStrip::kSpacing + strip.gap * (k - 5.5), 0.5, 0};
      double px, py;
      camera.project(centre, px, py);
      EXPECT_TRUE(test::is_background(image, static_cast<int>(px), static_cast<int>(py), s.background)) << "cut " << k;
    }
    EXPECT_GT(test::count_components(image, s.background), 1);
  }
}

// A triangle crossed by more than kMaxCutsPerTriangle cuts is not drawn (documented
// limit): with tessellation 1 both triangles cross all 10 cuts.
TEST(RenderManyEnrichments, TriangleCrossedByTooManyCutsIsDropped) {
  const SlicedStrip strip(0.08, 0.05);
  RenderSettings s = top_view(strip);
  s.tessellation = 1;
  const Image image = renderer().render(strip.state, s);
  EXPECT_EQ(renderer().last_triangles_submitted(), 2);
  EXPECT_EQ(renderer().last_triangles_drawn(), 0);
  EXPECT_EQ(test::count_components(image, s.background), 0);
}

// The most enrichments an element may have still compiles and draws (GL 3.3 limits on
// the geometry stage's output do not depend on the slot count); the cuts take the last
// slots (up to bit 31 of the shaders' slot masks).
TEST(RenderManyEnrichments, MaximumSlotCountRenders) {
  SlicedStrip strip(0.08, 0.05);
  ElementEnrichment inert = strip.state.enrichments[0];  // H = +1 everywhere, no DOFs: moves nothing
  std::fill(inert.values.begin(), inert.values.end(), 1.0f);
  std::fill(inert.node_values.begin(), inert.node_values.end(), 1.0f);
  std::fill(inert.dofs.begin(), inert.dofs.end(), 0.0);
  const int padding = kMaxEnrichmentsPerElement - SlicedStrip::kCuts;
  strip.state.enrichments.insert(strip.state.enrichments.begin(), padding, inert);
  RenderSettings s = top_view(strip);
  s.tessellation = 16;
  const Image image = renderer().render(strip.state, s);
  EXPECT_EQ(test::count_components(image, s.background), 11);
  strip.state.enrichments.push_back(inert);
  EXPECT_THROW(renderer().render(strip.state, s), std::invalid_argument);
}

}  // namespace
}  // namespace dgtex
