// Wall-aware adaptive enriched quadrature (enriched_quadrature.h): a straight wall through
// the element splits the quadtree AT the wall, so with smooth textures on both sides the
// two sides merge into a handful of cells instead of refining to single texels along the
// whole wall (the halving rule put >= 2 rows x T texels x 4 points there). Checked:
//  - two quadratics separated by a full straight wall (quad8, horizontal and vertical;
//    tri6): the moments of H, |grad H|^2 and the Hessian integrate to round-off (1e-12
//    relative) against the analytic values (quad8) and the per-texel rule (both), with
//    exactly 2 x 9 points on quad8 and far fewer points than the wall's texels alone took;
//  - no wall, quadratic H: the standard element rule (unchanged exactness);
//  - harmonic enrichments of partial straight cuts: the same integrals within the merge
//    tolerance's scale of the per-texel rule, and serial == parallel bitwise.
#include <gtest/gtest.h>
#include <omp.h>

#include <array>
#include <cmath>
#include <vector>

#include "dgtex/harmonic_enrichment.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/enriched_quadrature.h"
#include "dgtex/mesh_generators.h"

using namespace dgtex;

namespace {

// c0 + cx x + cy y + cxx x^2 + cxy x y + cyy y^2 in texel units, with exact derivatives.
struct Quadratic {
  double c0, cx, cy, cxx, cxy, cyy;
  double operator()(double x, double y) const { return c0 + cx * x + cy * y + cxx * x * x + cxy * x * y + cyy * y * y; }
  double dx(double x, double y) const { return cx + 2 * cxx * x + cxy * y; }
  double dy(double x, double y) const { return cy + cxy * x + 2 * cyy * y; }
};

// A single element with the given textures: everything enriched_element_quadrature reads
// (the geometry is a valid unit element; the quadrature does not look at it).
struct OneElement {
  ElementType type;
  int t;
  Mesh mesh;
  std::vector<kernels::TexelTile> tiles;
  std::vector<kernels::TextureView> views;
  std::vector<int> element{0}, start, nodes;
  std::vector<double> shifts;
  std::vector<kernels::ShellSection> sections{{1e6, 0.3, 0.01, 1000}};

  OneElement(ElementType element_type, int resolution, std::vector<kernels::TexelTile> textures)
      : type(element_type), t(resolution), mesh(make_rectangle(1.0, 1.0, 1, 1, element_type)), tiles(std::move(textures)) {
    const int npe = kernels::nodes_per_element(type);
    start = {0, static_cast<int>(tiles.size())};
    for (const kernels::TexelTile& tile : tiles) {
      views.push_back({tile.values.data(), tile.flags.data()});
      for (int a = 0; a < npe; ++a) nodes.push_back(-1), shifts.push_back(0.0);
    }
  }
  kernels::EnrichedElementBatch batch() const {
    return {type, 1, element.data(), mesh.elements.data(), mesh.positions.data(), sections.data(),
            t, kernels::nodes_per_element(type) * (1 + static_cast<int>(tiles.size())), start.data(),
            views.data(), nodes.data(), shifts.data()};
  }
  std::vector<double> points(bool adaptive, double tolerance, kernels::Execution execution = kernels::Execution::parallel) const {
    kernels::EnrichedQuadratureOptions options;
    options.adaptive = adaptive;
    options.merge_tolerance = tolerance;
    std::vector<std::int64_t> qp_start;
    std::vector<double> qp;
    kernels::enriched_element_quadrature(batch(), options, qp_start, qp, execution);
    EXPECT_EQ(qp_start.size(), 2u);
    EXPECT_EQ(static_cast<std::size_t>(qp_start[1]) * 3, qp.size());
    return qp;
  }
};

// Integrals of the first texture over the element by a point list: H, H xi1, H xi2,
// |grad H|^2, H_11 + H_22 + H_12 (all polynomials of degree <= 3 per direction when H is
// one quadratic per cell: exact for the per-texel and the merged rules).
std::array<double, 5> moments(const OneElement& e, const std::vector<double>& qp) {
  std::array<double, 5> m{};
  for (std::size_t q = 0; q < qp.size() / 3; ++q) {
    const double xi1 = qp[3 * q], xi2 = qp[3 * q + 1], w = qp[3 * q + 2];
    kernels::TextureSample s;
    kernels::sample_texture(e.type, e.t, e.views[0], xi1, xi2, s);
    m[0] += w * s.value;
    m[1] += w * s.value * xi1;
    m[2] += w * s.value * xi2;
    m[3] += w * (s.d[0] * s.d[0] + s.d[1] * s.d[1]);
    m[4] += w * (s.d2[0] + s.d2[1] + s.d2[2]);
  }
  return m;
}

double relative_difference(const std::array<double, 5>& a, const std::array<double, 5>& b) {
  double scale = 0, diff = 0;
  for (int k = 0; k < 5; ++k) scale = std::max(scale, std::abs(b[k])), diff = std::max(diff, std::abs(a[k] - b[k]));
  return diff / scale;
}

// Texels below the line y = line (texel units; horizontal) or left of x = line (vertical)
// take `low`, the others `high`; a wall separates them along the whole line.
kernels::TexelTile two_quadratics(ElementType type, int t, bool horizontal, int line, const Quadratic& low,
                                  const Quadratic& high) {
  kernels::TexelTile tile = kernels::make_element_tile(type, t);
  for (int j = 0; j < t; ++j)
    for (int i = 0; i < t; ++i) {
      if (tile.flags[tile.index(i, j)] & kernels::inactive) continue;
      const double x = i + 0.5, y = j + 0.5;
      const bool below = horizontal ? j < line : i < line;
      tile.values[tile.index(i, j)] = below ? low(x, y) : high(x, y);
      if (horizontal && j == line - 1) tile.flags[tile.index(i, j)] |= kernels::wall_north;
      if (!horizontal && i == line - 1) tile.flags[tile.index(i, j)] |= kernels::wall_east;
    }
  return tile;
}

constexpr int kT = 64;
const Quadratic kLow{0.3, 0.01, -0.02, 1e-4, 2e-4, 0};
const Quadratic kHigh{-0.7, 0.005, 0.01, 0, 1e-4, -3e-4};

// Exact moments of the quad8 two-quadratic texture by 4 x 4 Gauss on each side's rectangle.
std::array<double, 5> exact_quad8_moments(bool horizontal, int line) {
  std::array<double, 5> m{};
  const double g[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  const double gw[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  const double texel = 2.0 / kT;  // parametric size of a texel
  for (int side = 0; side < 2; ++side) {
    // The side's rectangle in texel units.
    double x0 = 0, x1 = kT, y0 = 0, y1 = kT;
    double& lo = horizontal ? y0 : x0;
    double& hi = horizontal ? y1 : x1;
    (side == 0 ? hi : lo) = line;
    const Quadratic& p = side == 0 ? kLow : kHigh;
    for (int b = 0; b < 4; ++b)
      for (int a = 0; a < 4; ++a) {
        const double x = x0 + 0.5 * (x1 - x0) * (1 + g[a]), y = y0 + 0.5 * (y1 - y0) * (1 + g[b]);
        const double w = 0.25 * (x1 - x0) * (y1 - y0) * gw[a] * gw[b] * texel * texel;
        const double v = p(x, y);
        const double dx = p.dx(x, y) / texel, dy = p.dy(x, y) / texel;
        const double dxx = 2 * p.cxx / (texel * texel), dyy = 2 * p.cyy / (texel * texel), dxy = p.cxy / (texel * texel);
        const double xi1 = -1 + x * texel, xi2 = -1 + y * texel;
        m[0] += w * v;
        m[1] += w * v * xi1;
        m[2] += w * v * xi2;
        m[3] += w * (dx * dx + dy * dy);
        m[4] += w * (dxx + dyy + dxy);
      }
  }
  return m;
}

TEST(EnrichedQuadratureWalls, StraightWallQuad8MergesBothSidesExactly) {
  for (bool horizontal : {true, false}) {
    const int line = 23;  // off the quadtree's halves on purpose
    OneElement e(ElementType::quad8, kT, {two_quadratics(ElementType::quad8, kT, horizontal, line, kLow, kHigh)});
    const std::vector<double> adaptive = e.points(true, 1e-9), dense = e.points(false, 1e-9);
    const std::array<double, 5> exact = exact_quad8_moments(horizontal, line);
    const double err_adaptive = relative_difference(moments(e, adaptive), exact);
    const double err_dense = relative_difference(moments(e, dense), exact);
    std::printf("quad8 %s wall: %zu adaptive points (per-texel %zu); moment errors %.2e (adaptive), %.2e (per-texel)\n",
                horizontal ? "horizontal" : "vertical", adaptive.size() / 3, dense.size() / 3, err_adaptive, err_dense);
    // One merged cell (3 x 3 Gauss) per side; the halving rule refined the wall's two
    // rows of texels to single texels (>= 2 * 64 * 4 = 512 points).
    EXPECT_EQ(adaptive.size() / 3, 18u);
    EXPECT_EQ(dense.size() / 3, 4u * kT * kT);
    EXPECT_LT(err_adaptive, 1e-12);
    EXPECT_LT(err_dense, 1e-12);
    double area = 0;
    for (std::size_t q = 0; q < adaptive.size() / 3; ++q) area += adaptive[3 * q + 2];
    EXPECT_NEAR(area, 4.0, 1e-13);
  }
}

TEST(EnrichedQuadratureWalls, StraightWallTri6MatchesPerTexelRule) {
  for (bool horizontal : {true, false}) {
    const int line = 21;
    OneElement e(ElementType::tri6, kT, {two_quadratics(ElementType::tri6, kT, horizontal, line, kLow, kHigh)});
    const std::vector<double> adaptive = e.points(true, 1e-9), dense = e.points(false, 1e-9);
    const double err = relative_difference(moments(e, adaptive), moments(e, dense));
    const std::size_t wall_texels = kT - line;  // texels along the wall inside the triangle
    std::printf("tri6 %s wall: %zu adaptive points (per-texel %zu); moments vs per-texel %.2e\n",
                horizontal ? "horizontal" : "vertical", adaptive.size() / 3, dense.size() / 3, err);
    EXPECT_LT(err, 1e-12);
    // Fewer points in the whole element than the halving rule put on the wall's two rows.
    EXPECT_LT(adaptive.size() / 3, 2 * wall_texels * 4);
    double area = 0;
    for (std::size_t q = 0; q < adaptive.size() / 3; ++q) area += adaptive[3 * q + 2];
    EXPECT_NEAR(area, 0.5, 1e-13);
  }
}

// (tri6 with a constant: its corner texels have one-sided neighbours only in one direction,
// where the texel rule drops the curvature, so only constants are one polynomial there.)
TEST(EnrichedQuadratureWalls, NoWallQuadraticIsTheStandardRule) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const Quadratic h = type == ElementType::quad8 ? kHigh : Quadratic{0.4, 0, 0, 0, 0, 0};
    kernels::TexelTile tile = two_quadratics(type, kT, true, 0, h, h);  // line 0: no wall
    OneElement e(type, kT, {tile});
    const std::vector<double> adaptive = e.points(true, 1e-9);
    const kernels::QuadratureRule r = kernels::element_quadrature(type);
    ASSERT_EQ(adaptive.size(), 3u * r.count);
    for (int q = 0; q < r.count; ++q) {
      EXPECT_EQ(adaptive[3 * q], r.xi1[q]);
      EXPECT_EQ(adaptive[3 * q + 1], r.xi2[q]);
      EXPECT_EQ(adaptive[3 * q + 2], r.weight[q]);
    }
  }
}

// Partial straight cuts from alternating borders (an accordion), harmonic enrichments.
OneElement accordion(ElementType type, int t, int cuts) {
  kernels::TexelTile walls = kernels::make_element_tile(type, t);
  std::vector<kernels::CutRaster> rasters;
  for (int k = 0; k < cuts; ++k) {
    std::vector<kernels::TexelPoint> line;
    if (type == ElementType::quad8) {  // alternating borders, along texel edges
      const double y = std::floor(t * (k + 0.7) / cuts);  // off the quadtree halves
      if (k % 2 == 0) line = {{0, y}, {0.8 * t, y}};
      else line = {{1.0 * t, y}, {0.2 * t, y}};
    } else {  // tri6: from the left border, 60% of the way to the hypotenuse
      const double y = std::floor(0.6 * t * (k + 1) / (cuts + 1));
      line = {{0, y}, {std::floor(0.6 * (t - y)), y}};
    }
    rasters.push_back(kernels::rasterize_cut(line, walls));
  }
  std::vector<kernels::TexelTile> tiles;
  for (int k = 0; k < cuts; ++k) tiles.push_back(harmonic_enrichment(walls, rasters[k]).tile);
  return OneElement(type, t, std::move(tiles));
}

TEST(EnrichedQuadratureWalls, HarmonicPartialCutsWithinToleranceOfPerTexelRule) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const OneElement e = accordion(type, kT, 3);
    const std::vector<double> dense = e.points(false, 1e-2);
    const std::array<double, 5> reference = moments(e, dense);
    for (double tolerance : {1e-2, 1e-3}) {
      const std::vector<double> adaptive = e.points(true, tolerance);
      // |grad H|^2 (index 3) carries the tips' singularity; H moments are smooth.
      std::array<double, 5> a = moments(e, adaptive);
      double worst = 0;
      for (int k = 0; k < 4; ++k) worst = std::max(worst, std::abs(a[k] - reference[k]) / std::max(1e-3, std::abs(reference[k])));
      std::printf("%s accordion, tol %.0e: %zu points (per-texel %zu); H and |grad H|^2 moments vs per-texel %.2e\n",
                  type == ElementType::quad8 ? "quad8" : "tri6", tolerance, adaptive.size() / 3, dense.size() / 3, worst);
      EXPECT_LT(worst, tolerance);
      EXPECT_LT(adaptive.size(), dense.size());
      const std::vector<double> serial = e.points(true, tolerance, kernels::Execution::serial);
      EXPECT_EQ(serial, adaptive);
    }
  }
}

}  // namespace
