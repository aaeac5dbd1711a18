// The fast enriched quadrature (enriched_quadrature.h) against its serial reference twin:
// the point arrays (start offsets, points, weights, order) must be BITWISE identical for
// every input and every thread count (serial, and parallel with 1, 2 and 3 threads).
// Inputs: two quadratics split by a straight wall (quad8 and tri6, tolerances that merge and
// that do not), harmonic enrichments of partial straight cuts (an accordion) and of a
// partial spiral, Heaviside textures of complete staircase cuts, random textures with random
// walls and inactive texels (odd T, so no split is a clean half), the per-texel rule, and
// batches of several elements with different texture counts (0 included).
// Also texel_derivative_rows against texel_derivatives (enriched_basis.h), bitwise.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "dgtex/harmonic_enrichment.h"
#include "dgtex/heaviside.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/enriched_quadrature.h"
#include "dgtex/kernels/texel_derivative_rows.h"
#include "dgtex/mesh_generators.h"
#include "thread_count_support.h"

using namespace dgtex;

namespace {

// Elements (any geometry: the quadrature reads only the textures) with given textures each.
struct Batch {
  ElementType type;
  int t;
  Mesh mesh;
  std::vector<std::vector<kernels::TexelTile>> tiles;  // per element
  std::vector<kernels::TextureView> views;
  std::vector<int> element, start{0}, nodes;
  std::vector<double> shifts;
  std::vector<kernels::ShellSection> sections;
  int width = 0;

  Batch(ElementType element_type, int resolution, std::vector<std::vector<kernels::TexelTile>> textures)
      : type(element_type), t(resolution), mesh(make_rectangle(1.0, 1.0, std::max(1, static_cast<int>(textures.size())), 1, element_type)),
        tiles(std::move(textures)) {
    const int npe = kernels::nodes_per_element(type);
    for (std::size_t e = 0; e < tiles.size(); ++e) {
      element.push_back(static_cast<int>(e));
      for (const kernels::TexelTile& tile : tiles[e]) {
        views.push_back({tile.values.data(), tile.flags.data()});
        for (int a = 0; a < npe; ++a) nodes.push_back(-1), shifts.push_back(0.0);
      }
      start.push_back(static_cast<int>(views.size()));
      width = std::max(width, npe * (1 + static_cast<int>(tiles[e].size())));
    }
    sections.assign(mesh.num_elements(), {1e6, 0.3, 0.01, 1000});
  }
  kernels::EnrichedElementBatch batch() const {
    return {type, static_cast<std::int64_t>(tiles.size()), element.data(), mesh.elements.data(), mesh.positions.data(),
            sections.data(), t, width, start.data(), views.data(), nodes.data(), shifts.data()};
  }
};

template <class T>
bool bitwise_equal(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

// The reference once, the fast form serial and with 1, 2, 3 threads: all bitwise equal.
// Returns the number of points (so callers can check the input exercised merging).
std::int64_t expect_fast_equals_reference(const Batch& b, bool adaptive, double tolerance, const char* what) {
  kernels::EnrichedQuadratureOptions options;
  options.adaptive = adaptive;
  options.merge_tolerance = tolerance;
  std::vector<std::int64_t> ref_start, start;
  std::vector<double> ref_points, points;
  kernels::enriched_element_quadrature_reference(b.batch(), options, ref_start, ref_points);
  EXPECT_EQ(ref_start.size(), b.tiles.size() + 1);
  EXPECT_EQ(static_cast<std::size_t>(ref_start.back()) * 3, ref_points.size());
  kernels::enriched_element_quadrature(b.batch(), options, start, points, kernels::Execution::serial);
  EXPECT_TRUE(bitwise_equal(start, ref_start)) << what << ": serial start offsets differ";
  EXPECT_TRUE(bitwise_equal(points, ref_points)) << what << ": serial points differ (" << points.size() / 3 << " vs "
                                                 << ref_points.size() / 3 << " points)";
  for (int threads : {1, 2, 3}) {
    const test::ThreadCountGuard set_threads(threads);
    start.assign(3, -7);  // stale contents must not survive
    points.assign(5, -7.0);
    kernels::enriched_element_quadrature(b.batch(), options, start, points, kernels::Execution::parallel);
    EXPECT_TRUE(bitwise_equal(start, ref_start)) << what << ": start offsets differ with " << threads << " threads";
    EXPECT_TRUE(bitwise_equal(points, ref_points)) << what << ": points differ with " << threads << " threads";
  }
  return ref_start.back();
}

struct Quadratic {
  double c0, cx, cy, cxx, cxy, cyy;
  double operator()(double x, double y) const { return c0 + cx * x + cy * y + cxx * x * x + cxy * x * y + cyy * y * y; }
};

kernels::TexelTile two_quadratics(ElementType type, int t, bool horizontal, int line, const Quadratic& low,
                                  const Quadratic& high) {
  kernels::TexelTile tile = kernels::make_element_tile(type, t);
  for (int j = 0; j < t; ++j)
    for (int i = 0; i < t; ++i) {
      if (tile.flags[tile.index(i, j)] & kernels::inactive) continue;
      const bool below = horizontal ? j < line : i < line;
      tile.values[tile.index(i, j)] = below ? low(i + 0.5, j + 0.5) : high(i + 0.5, j + 0.5);
      if (horizontal && j == line - 1) tile.flags[tile.index(i, j)] |= kernels::wall_north;
      if (!horizontal && i == line - 1) tile.flags[tile.index(i, j)] |= kernels::wall_east;
    }
  return tile;
}

// Harmonic enrichments of partial cuts given as texel-space polylines (one texture each).
std::vector<kernels::TexelTile> harmonic_textures(ElementType type, int t, const std::vector<std::vector<kernels::TexelPoint>>& lines) {
  kernels::TexelTile walls = kernels::make_element_tile(type, t);
  std::vector<kernels::CutRaster> rasters;
  for (const auto& line : lines) rasters.push_back(kernels::rasterize_cut(line, walls));
  std::vector<kernels::TexelTile> tiles;
  for (const auto& raster : rasters) tiles.push_back(harmonic_enrichment(walls, raster).tile);
  return tiles;
}

std::vector<std::vector<kernels::TexelPoint>> accordion_lines(ElementType type, int t, int cuts) {
  std::vector<std::vector<kernels::TexelPoint>> lines;
  for (int k = 0; k < cuts; ++k) {
    if (type == ElementType::quad8) {
      const double y = std::floor(t * (k + 0.7) / cuts);
      if (k % 2 == 0) lines.push_back({{0, y}, {0.8 * t, y}});
      else lines.push_back({{1.0 * t, y}, {0.2 * t, y}});
    } else {
      const double y = std::floor(0.6 * t * (k + 1) / (cuts + 1));
      lines.push_back({{0, y}, {std::floor(0.6 * (t - y)), y}});
    }
  }
  return lines;
}

// A spiral from the tile border inwards (one partial cut), as in the spiral scenes.
std::vector<kernels::TexelPoint> spiral_line(ElementType type, int t) {
  std::vector<kernels::TexelPoint> line;
  const double cx = type == ElementType::quad8 ? 0.5 * t : 0.33 * t, cy = cx;
  const double r0 = type == ElementType::quad8 ? 0.5 * t : 0.33 * t;
  line.push_back({type == ElementType::quad8 ? 0.0 : 0.0, cy});
  for (int n = 0; n <= 160; ++n) {
    const double a = M_PI + 3.5 * M_PI * n / 160.0;
    const double r = r0 * (1 - 0.8 * n / 160.0);
    line.push_back({cx + r * std::cos(a) * 0.97, cy + r * std::sin(a) * 0.97});
  }
  return line;
}

// Heaviside textures of complete cuts (straight diagonal staircase and a bent one).
std::vector<kernels::TexelTile> complete_cut_textures(ElementType type, int t) {
  kernels::TexelTile walls = kernels::make_element_tile(type, t);
  const double s = type == ElementType::quad8 ? t : 0.999 * t;
  std::vector<std::vector<kernels::TexelPoint>> lines = {{{0, 0.3 * s}, {s, 0.55 * s}},
                                                         {{0.2 * s, 0}, {0.35 * s, 0.3 * s}, {0.25 * s, type == ElementType::quad8 ? s : 0.75 * s}}};
  std::vector<kernels::CutRaster> rasters;
  for (const auto& line : lines) rasters.push_back(kernels::rasterize_cut(line, walls));
  std::vector<kernels::TexelTile> tiles;
  for (const auto& raster : rasters) tiles.push_back(complete_cut_heaviside(walls, raster));
  return tiles;
}

// Random walls and inactive texels; values either noise or a smooth field (so that some
// cells merge and some fail late).
kernels::TexelTile random_texture(ElementType type, int t, unsigned seed, bool smooth) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  kernels::TexelTile tile(t, t);  // any T (make_element_tile takes powers of two only)
  for (int j = 0; j < t; ++j)
    for (int i = 0; i < t; ++i) {
      std::uint8_t& f = tile.flags[tile.index(i, j)];
      if (type == ElementType::tri6 && i + j > t - 1) f |= kernels::inactive;
      const double x = (i + 0.5) / t, y = (j + 0.5) / t;
      tile.values[tile.index(i, j)] = smooth ? std::sin(2.0 * x) * std::cos(1.3 * y) + 0.1 * x * y : u(rng) - 0.5;
      const double r = u(rng);
      if (r < 0.02) f |= kernels::wall_east;
      else if (r < 0.04) f |= kernels::wall_north;
      else if (r < 0.045) f |= kernels::wall_east | kernels::wall_north;
      if (u(rng) < 0.01) f |= kernels::inactive;
    }
  // A long straight wall run (a wall line that splits cells) through part of the tile.
  for (int i = t / 5; i < t - t / 4; ++i) tile.flags[tile.index(i, t / 3)] |= kernels::wall_north;
  return tile;
}

constexpr int kT = 64;
const Quadratic kLow{0.3, 0.01, -0.02, 1e-4, 2e-4, 0};
const Quadratic kHigh{-0.7, 0.005, 0.01, 0, 1e-4, -3e-4};

TEST(EnrichedQuadratureSpeed, TexelDerivativeRowsEqualTexelDerivatives) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6})
    for (int t : {1, 2, 3, 5, 37, 64})
      for (bool smooth : {false, true}) {
        const kernels::TexelTile tile = random_texture(type, t, 11u * t + (smooth ? 1 : 0), smooth);
        const kernels::TextureView view{tile.values.data(), tile.flags.data()};
        // Whole tile at once and in uneven row blocks: same results.
        for (int block : {t, 3, 16}) {
          std::vector<double> planes(6 * static_cast<std::size_t>(t) * t, -1.0);
          const auto plane = [&](int p) { return planes.data() + static_cast<std::size_t>(p) * t * t; };
          for (int j = 0; j < t; j += block) {
            const std::size_t o = static_cast<std::size_t>(j) * t;
            kernels::texel_derivative_rows(type, t, view, j, j + block,
                                           {plane(0) + o, {plane(1) + o, plane(2) + o}, {plane(3) + o, plane(4) + o, plane(5) + o}});
          }
          int checked = 0;
          for (int j = 0; j < t; ++j)
            for (int i = 0; i < t; ++i) {
              kernels::TexelDerivatives ref;  // zeros outside the domain
              if (kernels::texel_in_domain(type, t, tile.flags.data(), i, j)) {
                kernels::texel_derivatives(type, t, view, i, j, ref);
                ++checked;
              }
              const std::size_t n = static_cast<std::size_t>(j) * t + i;
              const double a[6] = {ref.value, ref.g[0], ref.g[1], ref.s[0], ref.s[1], ref.s[2]};
              const double b[6] = {plane(0)[n], plane(1)[n], plane(2)[n], plane(3)[n], plane(4)[n], plane(5)[n]};
              ASSERT_EQ(std::memcmp(a, b, sizeof a), 0) << "texel " << i << "," << j << " T " << t << " block " << block;
            }
          EXPECT_GT(checked, 0);
        }
      }
}

TEST(EnrichedQuadratureSpeed, StraightWallsBitwiseEqualReference) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6})
    for (bool horizontal : {true, false})
      for (double tolerance : {1e-9, 1e-2, 0.0}) {
        const Batch b(type, kT, {{two_quadratics(type, kT, horizontal, 23, kLow, kHigh)}});
        expect_fast_equals_reference(b, true, tolerance, "straight wall");
      }
}

TEST(EnrichedQuadratureSpeed, HarmonicPartialCutsBitwiseEqualReference) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const Batch accordion(type, kT, {harmonic_textures(type, kT, accordion_lines(type, kT, 3))});
    const Batch spiral(type, 128, {harmonic_textures(type, 128, {spiral_line(type, 128)})});
    for (double tolerance : {1e-2, 1e-3, 1e-4}) {
      const std::int64_t n = expect_fast_equals_reference(accordion, true, tolerance, "accordion");
      const std::int64_t dense = expect_fast_equals_reference(accordion, false, tolerance, "accordion per-texel");
      EXPECT_LT(n, dense);  // the input exercises merging
      expect_fast_equals_reference(spiral, true, tolerance, "spiral");
    }
  }
}

TEST(EnrichedQuadratureSpeed, CompleteCutsBitwiseEqualReference) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6})
    for (int t : {kT, 32}) {
      const Batch b(type, t, {complete_cut_textures(type, t)});
      expect_fast_equals_reference(b, true, 1e-2, "complete cuts");
      expect_fast_equals_reference(b, true, 0.0, "complete cuts, tolerance 0");
    }
}

TEST(EnrichedQuadratureSpeed, RandomWallsAndInactiveTexelsBitwiseEqualReference) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6})
    for (int t : {1, 2, 7, 37}) {
      const Batch b(type, t, {{random_texture(type, t, 3u * t, true)}, {random_texture(type, t, 5u * t, false)},
                              {random_texture(type, t, 7u * t, true), random_texture(type, t, 9u * t, true)}});
      for (double tolerance : {1e-1, 1e-2, 1.0})
        for (bool adaptive : {true, false}) expect_fast_equals_reference(b, adaptive, tolerance, "random");
    }
}

TEST(EnrichedQuadratureSpeed, EmptyBatchGivesNoPoints) {
  const Batch b(ElementType::quad8, 8, {});
  std::vector<std::int64_t> start{5, 6};
  std::vector<double> points{1.0};
  kernels::enriched_element_quadrature(b.batch(), {}, start, points);
  EXPECT_EQ(start, std::vector<std::int64_t>{0});
  EXPECT_TRUE(points.empty());
}

TEST(EnrichedQuadratureSpeed, MultiElementBatchesBitwiseEqualReference) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const int t = 32;
    std::vector<std::vector<kernels::TexelTile>> textures;
    textures.push_back(harmonic_textures(type, t, accordion_lines(type, t, 2)));
    textures.push_back({});  // an element without textures: the standard rule
    textures.push_back(complete_cut_textures(type, t));
    textures.push_back({two_quadratics(type, t, false, 17, kLow, kHigh)});
    textures.push_back({random_texture(type, t, 99u, true)});
    const Batch b(type, t, std::move(textures));
    for (bool adaptive : {true, false}) expect_fast_equals_reference(b, adaptive, 1e-2, "batch");
  }
}

}  // namespace
