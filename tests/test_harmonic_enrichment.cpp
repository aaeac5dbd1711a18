// Harmonic enrichment (thesis §5.5): the crack-tip function sqrt(r) sin(theta/2) near the
// tip of a straight partial cut (Fig. 5.13), symmetry and the maximum principle for +-1
// data, convergence to the Heaviside as a cut completes, the App. A.2 span property for
// 2 and 3 complete cuts meeting at junctions, Neumann-only components, degenerate cuts,
// and the one-ring block solve of §5.5.3 (quad8 with turned neighbours, tri6 pairs).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "dgtex/harmonic_enrichment.h"
#include "dgtex/heaviside.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/laplace_direct.h"

using namespace dgtex;
using kernels::ElementType;
using kernels::TexelTile;

namespace {

double crack_tip_function(double x, double y, double tip_x, double tip_y) {
  const double r = std::hypot(x - tip_x, y - tip_y);
  return std::sqrt(r) * std::sin(0.5 * std::atan2(y - tip_y, x - tip_x));
}

double max_abs(const std::vector<double>& v) {
  double m = 0;
  for (double x : v) m = std::max(m, std::abs(x));
  return m;
}

// Columns: the sampled functions over the active texels.
Eigen::MatrixXd sample_matrix(const TexelTile& domain, const std::vector<std::vector<double>>& functions) {
  std::vector<int> active;
  for (std::size_t t = 0; t < domain.flags.size(); ++t)
    if (!(domain.flags[t] & kernels::inactive)) active.push_back(static_cast<int>(t));
  Eigen::MatrixXd m(active.size(), functions.size());
  for (std::size_t c = 0; c < functions.size(); ++c)
    for (std::size_t r = 0; r < active.size(); ++r) m(r, c) = functions[c][active[r]];
  return m;
}

int numerical_rank(const Eigen::MatrixXd& m) {
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(m);
  const auto& s = svd.singularValues();
  int rank = 0;
  for (int k = 0; k < s.size(); ++k) rank += s[k] > 1e-9 * s[0];
  return rank;
}

// Harmonic enrichments of every cut, with the walls of all cuts in the tile.
struct CutSet {
  TexelTile tile;
  std::vector<kernels::CutRaster> cuts;
};
CutSet rasterize_all(int t, const std::vector<std::vector<kernels::TexelPoint>>& polylines) {
  CutSet set{TexelTile(t, t), {}};
  for (const auto& line : polylines) set.cuts.push_back(kernels::rasterize_cut(line, set.tile));
  return set;
}

// Checks span{1, H^1..H^n} == span{indicators of the components}; returns the ranks.
void expect_span_equals_components(const CutSet& set, int expected_components) {
  std::vector<std::vector<double>> harmonic = {std::vector<double>(set.tile.values.size(), 1.0)};
  for (const auto& cut : set.cuts) {
    const HarmonicEnrichment h = harmonic_enrichment(set.tile, cut);
    // The same problem through a plain CHOLMOD solve: equal to solver accuracy.
    TexelTile direct = set.tile;
    set_cut_dirichlet(direct, cut);
    solve_laplace_direct(direct);
    for (std::size_t k = 0; k < direct.values.size(); ++k) ASSERT_NEAR(direct.values[k], h.tile.values[k], 1e-10);
    harmonic.push_back(direct.values);
  }
  std::vector<std::vector<double>> indicators;
  for (const auto& c : canonical_heavisides(set.tile)) indicators.push_back(c.values);
  ASSERT_EQ(static_cast<int>(indicators.size()), expected_components);
  const Eigen::MatrixXd a = sample_matrix(set.tile, harmonic), c = sample_matrix(set.tile, indicators);
  Eigen::MatrixXd both(a.rows(), a.cols() + c.cols());
  both << a, c;
  EXPECT_EQ(numerical_rank(a), expected_components);
  EXPECT_EQ(numerical_rank(c), expected_components);
  EXPECT_EQ(numerical_rank(both), expected_components);
  // Each indicator is reproduced from {1, H^i} by least squares to round-off.
  const Eigen::MatrixXd coefficients = a.colPivHouseholderQr().solve(c);
  EXPECT_LT((a * coefficients - c).cwiseAbs().maxCoeff(), 1e-9);
}

}  // namespace

// Fig. 5.13: Dirichlet +-sqrt(r) on the texels beside a straight cut from the border to
// the tile centre and the analytic value on the outermost texel ring. The 5-point
// solution matches sqrt(r) sin(theta/2) in the annulus 4 <= r <= 32 texels (T = 128) to
// within 1 % of sqrt(r) (measured 0.63 %, largest at r = 4.3 where the singularity's
// discretisation error sits).
TEST(HarmonicEnrichment, PartialCutMatchesCrackTipFunctionNearTheTip) {
  const int t = 128;
  const double tip = 64.0;
  TexelTile tile(t, t);
  const auto cut = kernels::rasterize_cut({{0.0, tip}, {tip, tip}}, tile);
  ASSERT_EQ(cut.edges.size(), 64u);
  auto centre_x = [&](int texel) { return texel % t + 0.5; };
  auto centre_y = [&](int texel) { return texel / t + 0.5; };
  for (int j = 0; j < t; ++j)
    for (int i = 0; i < t; ++i)
      if (i == 0 || j == 0 || i == t - 1 || j == t - 1) {
        tile.flags[tile.index(i, j)] |= kernels::dirichlet;
        tile.values[tile.index(i, j)] = crack_tip_function(i + 0.5, j + 0.5, tip, tip);
      }
  const HarmonicEnrichment h = harmonic_enrichment(tile, cut, [&](int texel, int side) {
    return side * std::sqrt(std::hypot(centre_x(texel) - tip, centre_y(texel) - tip));
  });
  EXPECT_EQ(h.solved_components, 1);
  EXPECT_LT(h.stats.relative_residual, 1e-10);
  double worst = 0, worst_r = 0;
  int compared = 0;
  for (int k = 0; k < t * t; ++k) {
    const double x = centre_x(k), y = centre_y(k), r = std::hypot(x - tip, y - tip);
    if (r < 4.0 || r > 32.0) continue;
    const double relative = std::abs(h.tile.values[k] - crack_tip_function(x, y, tip, tip)) / std::sqrt(r);
    if (relative > worst) worst = relative, worst_r = r;
    ++compared;
  }
  std::printf("crack tip: max |H - sqrt(r) sin(theta/2)| / sqrt(r) = %.4f at r = %.2f over %d texels\n", worst, worst_r,
              compared);
  EXPECT_GT(compared, 3000);
  EXPECT_LT(worst, 0.01);
}

TEST(HarmonicEnrichment, PartialCutIsAntisymmetricAndBounded) {
  const int t = 64;
  TexelTile tile(t, t);
  const auto cut = kernels::rasterize_cut({{0.0, 32.0}, {32.0, 32.0}}, tile);
  const HarmonicEnrichment h = harmonic_enrichment(tile, cut);
  EXPECT_EQ(h.solved_components, 1);
  const auto& v = h.tile.values;
  EXPECT_LE(max_abs(v), 1.0);  // maximum principle
  for (int j = 0; j < t; ++j)
    for (int i = 0; i < t; ++i) ASSERT_NEAR(v[tile.index(i, j)], -v[tile.index(i, t - 1 - j)], 1e-10);
  for (const auto& e : cut.edges) {  // the discontinuity: +1 | -1 across every cut edge
    ASSERT_EQ(v[e.left_texel], 1.0);
    ASSERT_EQ(v[e.right_texel], -1.0);
  }
  // Ahead of the tip H is continuous: the step across y = 32 decays away from the tip.
  const double near_tip = v[tile.index(33, 32)] - v[tile.index(33, 31)];
  const double far_away = v[tile.index(60, 32)] - v[tile.index(60, 31)];
  EXPECT_LT(near_tip, 1.0);
  EXPECT_LT(far_away, 0.5 * near_tip);
  EXPECT_GT(far_away, 0.0);
}

TEST(HarmonicEnrichment, ConvergesToTheHeavisideAsTheCutCompletes) {
  const int t = 64;
  double previous = 1e300;
  for (double length : {40.0, 52.0, 58.0, 62.0, 64.0}) {
    TexelTile tile(t, t);
    const auto cut = kernels::rasterize_cut({{0.0, 21.0}, {length, 21.0}}, tile);
    const HarmonicEnrichment h = harmonic_enrichment(tile, cut);
    std::vector<double> difference(h.tile.values.size());
    for (int j = 0; j < t; ++j)
      for (int i = 0; i < t; ++i) difference[tile.index(i, j)] = h.tile.values[tile.index(i, j)] - (j >= 21 ? 1.0 : -1.0);
    const double distance = max_abs(difference);
    EXPECT_LT(distance, previous) << "cut length " << length;
    previous = distance;
    if (length == 64.0) {
      EXPECT_EQ(distance, 0.0);
    }
  }
}

TEST(HarmonicEnrichment, SpanOfTwoCutsMeetingAtAJunctionIsTheComponentSpace) {
  // Fig. 5.7: a complete cut and a second one ending on it: 3 components.
  expect_span_equals_components(rasterize_all(64, {{{0, 32}, {64, 32}}, {{24.3, 0}, {24.0, 32.2}}}), 3);
}

TEST(HarmonicEnrichment, SpanOfThreeCutsMeetingAtJunctionsIsTheComponentSpace) {
  // A wavy complete cut, one ending on it from below, one from above (slanted): 4 components.
  expect_span_equals_components(
      rasterize_all(64, {{{0, 30}, {20, 36}, {40, 28}, {64, 33}}, {{12.0, 0.0}, {15.0, 34.5}}, {{56.0, 64.0}, {40.0, 28.0}}}), 4);
}

// Two cuts crossing each other make 4 components but {1, H^1, H^2} spans only 3
// dimensions (App. A.2 assumes every cut ends at the boundary or at a junction);
// split_cut_at_crossings splits the later cut where it meets earlier cuts or the
// boundary, which restores the full span.
CutSet split_later_cut(int t, const std::vector<kernels::TexelPoint>& earlier, const std::vector<kernels::TexelPoint>& later) {
  CutSet set{TexelTile(t, t), {}};
  set.cuts.push_back(kernels::rasterize_cut(earlier, set.tile));
  const TexelTile earlier_walls = set.tile;
  for (auto& piece : kernels::split_cut_at_crossings(kernels::rasterize_cut(later, set.tile), earlier_walls))
    set.cuts.push_back(piece);
  return set;
}

TEST(HarmonicEnrichment, CrossingCutsSplitAtTheCrossingSpanTheComponentSpace) {
  const CutSet crossing = rasterize_all(32, {{{0, 16}, {32, 16}}, {{16, 0}, {16, 32}}});
  std::vector<std::vector<double>> harmonic = {std::vector<double>(32 * 32, 1.0)};
  for (const auto& cut : crossing.cuts) harmonic.push_back(harmonic_enrichment(crossing.tile, cut).tile.values);
  EXPECT_EQ(numerical_rank(sample_matrix(crossing.tile, harmonic)), 3);
  EXPECT_EQ(canonical_heavisides(crossing.tile).size(), 4u);

  const CutSet split = split_later_cut(32, {{0, 16}, {32, 16}}, {{16, 0}, {16, 32}});
  ASSERT_EQ(split.cuts.size(), 3u);
  expect_span_equals_components(split, 4);
  // A slanted cut crossing a wavy one twice and touching the top edge in between: split
  // at both crossings and at the touch, 1 + 4 cuts for 6 components.
  const CutSet wavy = split_later_cut(64, {{0, 30}, {20, 36}, {40, 28}, {64, 33}},
                                      {{5, 0}, {14, 50}, {30, 63.5}, {50, 10}, {60, 0}});
  EXPECT_EQ(wavy.cuts.size(), 5u);
  expect_span_equals_components(wavy, 6);
  // Touching an earlier cut and turning back: split at the touch, 1 + 2 cuts, 4 components.
  const CutSet touching = split_later_cut(32, {{0, 16}, {32, 16}}, {{4, 0}, {12, 16}, {20, 16}, {28, 0}});
  ASSERT_EQ(touching.cuts.size(), 3u);
  expect_span_equals_components(touching, 4);
}

TEST(HarmonicEnrichment, ComponentsReachedOnlyByNeumannBoundariesAreZero) {
  const int t = 64;
  CutSet set = rasterize_all(t, {{{40, 40}, {56, 40}, {56, 56}, {40, 56}, {40, 40}},  // a closed loop
                                  {{0, 20}, {30, 20}}});                               // a partial cut
  const HarmonicEnrichment h = harmonic_enrichment(set.tile, set.cuts[1]);
  for (int j = 40; j < 56; ++j)
    for (int i = 40; i < 56; ++i) ASSERT_EQ(h.tile.values[set.tile.index(i, j)], 0.0);
  EXPECT_GT(h.tile.values[set.tile.index(60, 60)], 0.0);  // above the cut's line
  // The loop's own enrichment: +1 inside (left of a counter-clockwise loop), -1 outside.
  const HarmonicEnrichment loop = harmonic_enrichment(set.tile, set.cuts[0]);
  EXPECT_EQ(loop.tile.values[set.tile.index(47, 47)], 1.0);
  EXPECT_EQ(loop.tile.values[set.tile.index(2, 2)], -1.0);
  EXPECT_EQ(loop.solved_components, 0);
}

TEST(HarmonicEnrichment, DegenerateCuts) {
  const int t = 32;
  {  // shorter than half a texel: no edges, H = 0 without a solve
    TexelTile tile(t, t);
    const auto cut = kernels::rasterize_cut({{10.1, 10.1}, {10.3, 10.2}}, tile);
    const HarmonicEnrichment h = harmonic_enrichment(tile, cut);
    EXPECT_EQ(max_abs(h.tile.values), 0.0);
    EXPECT_EQ(h.solved_components + h.constant_components, 0);
  }
  {  // along an element edge: one side only, H = +1 exactly (the neighbour holds -1)
    TexelTile tile(t, t);
    const auto cut = kernels::rasterize_cut({{0, 0}, {32, 0}}, tile);
    const HarmonicEnrichment h = harmonic_enrichment(tile, cut);
    for (double v : h.tile.values) ASSERT_EQ(v, 1.0);
  }
  {  // a fragment of 3 texels in the middle: an antisymmetric dipole decaying away from it
    TexelTile tile(t, t);
    const auto cut = kernels::rasterize_cut({{14.4, 16.0}, {17.4, 16.0}}, tile);
    ASSERT_EQ(cut.edges.size(), 3u);
    const HarmonicEnrichment h = harmonic_enrichment(tile, cut);
    for (int j = 0; j < t; ++j)
      for (int i = 0; i < t; ++i) ASSERT_NEAR(h.tile.values[tile.index(i, j)], -h.tile.values[tile.index(i, t - 1 - j)], 1e-10);
    for (int j = 16; j + 1 < t; ++j) {  // above it: positive, falling off with distance
      ASSERT_GT(h.tile.values[tile.index(15, j)], h.tile.values[tile.index(15, j + 1)]);
      ASSERT_GT(h.tile.values[tile.index(15, j + 1)], 0.0);
    }
    EXPECT_LE(max_abs(h.tile.values), 1.0);
  }
  {  // through a node: from the quad8 midside node (16, 0) up to the centre
    TexelTile tile(t, t);
    const auto cut = kernels::rasterize_cut({{16, 0}, {16, 16}}, tile);
    const HarmonicEnrichment h = harmonic_enrichment(tile, cut);
    for (int j = 0; j < t; ++j)
      for (int i = 0; i < t; ++i) ASSERT_NEAR(h.tile.values[tile.index(i, j)], -h.tile.values[tile.index(t - 1 - i, j)], 1e-10);
    EXPECT_EQ(h.tile.values[tile.index(15, 3)], 1.0);  // upward cut: west is its left
  }
  {  // self-intersecting: the loop it closes is +1, texels left of one pass and right of
     // the other take the mean 0, everything stays within [-1, 1]
    TexelTile tile(t, t);
    const auto cut = kernels::rasterize_cut({{8, 8}, {24, 8}, {24, 24}, {16, 24}, {16, 0}}, tile);
    const HarmonicEnrichment h = harmonic_enrichment(tile, cut);
    for (int j = 8; j < 24; ++j)
      for (int i = 16; i < 24; ++i) ASSERT_EQ(h.tile.values[tile.index(i, j)], 1.0);
    EXPECT_EQ(h.tile.values[tile.index(15, 8)], 0.0);  // above the first pass, west of the last
    EXPECT_TRUE(h.tile.flags[tile.index(15, 8)] & kernels::dirichlet);
    EXPECT_LE(max_abs(h.tile.values), 1.0);
    EXPECT_EQ(h.solved_components, 1);
  }
  {  // tri6: a partial cut from corner node 0 into the element; inactive texels stay 0
    TexelTile tile = kernels::make_element_tile(ElementType::tri6, t);
    const auto cut = kernels::rasterize_cut({{0, 0}, {10.2, 9.7}}, tile);
    const HarmonicEnrichment h = harmonic_enrichment(tile, cut);
    for (std::size_t k = 0; k < tile.flags.size(); ++k) {
      if (tile.flags[k] & kernels::inactive) {
        ASSERT_EQ(h.tile.values[k], 0.0);
      }
    }
    EXPECT_LE(max_abs(h.tile.values), 1.0);
    EXPECT_GT(h.tile.values[tile.index(2, 20)], 0.0);   // left of the up-right cut
    EXPECT_LT(h.tile.values[tile.index(20, 2)], 0.0);
  }
}

// §5.5.3: a one-ring block (3x3 quad8 tiles, each turned by a random orientation) with the
// 16 surrounding tiles as C0 Dirichlet neighbours reproduces the solve on the whole 5x5
// patch: the neighbours' values carry exactly the coupling the region sees there.
TEST(HarmonicEnrichment, OneRingBlockWithNeighbourDataReproducesTheWholePatch) {
  const int t = 16, n = 5 * t;
  const std::vector<kernels::TexelPoint> polyline = {{0.0, 37.3}, {20.2, 44.9}, {33.1, 31.2}, {40.6, 39.5}};
  TexelTile whole(n, n);
  const auto cut = kernels::rasterize_cut(polyline, whole);
  const HarmonicEnrichment global = harmonic_enrichment(whole, cut);
  ASSERT_EQ(global.solved_components, 1);

  std::mt19937 rng(5);
  const TexelTile blank(t, t);
  std::vector<TexelTile> local(25);
  std::vector<PlacedTile> placement;
  for (int by = 0; by < 5; ++by)
    for (int bx = 0; bx < 5; ++bx) {
      PlacedTile where{&blank, bx * t, by * t, static_cast<int>(rng() % 8), false};
      local[by * 5 + bx] = extract_tile(global.tile, where);  // the element's own tile, turned
      where.tile = &local[by * 5 + bx];
      where.dirichlet_neighbour = bx == 0 || by == 0 || bx == 4 || by == 4;
      if (!where.dirichlet_neighbour)  // region tiles: geometry only, the cut is re-applied
        for (auto& f : local[by * 5 + bx].flags) f &= static_cast<std::uint8_t>(~kernels::dirichlet);
      placement.push_back(where);
    }
  TexelTile block = assemble_tile_block(placement, n, n);
  const auto block_cut = kernels::rasterize_cut(polyline, block);
  const HarmonicEnrichment ring = harmonic_enrichment(block, block_cut);
  int compared = 0;
  for (int j = t; j < 4 * t; ++j)
    for (int i = t; i < 4 * t; ++i, ++compared)
      ASSERT_NEAR(ring.tile.values[block.index(i, j)], global.tile.values[whole.index(i, j)], 1e-9);
  EXPECT_EQ(compared, 9 * t * t);
  // Region texels read back through each placement equal the whole patch's values.
  for (const auto& where : placement) {
    if (where.dirichlet_neighbour) continue;
    const TexelTile back = extract_tile(ring.tile, where);
    for (int j = 0; j < t; ++j)
      for (int i = 0; i < t; ++i) {
        const auto b = block_texel(where, i, j);
        ASSERT_NEAR(back.values[back.index(i, j)], global.tile.values[whole.index(b[0], b[1])], 1e-9);
      }
  }
}

// Two tri6 tiles placed as one square (the second turned by 180°) share their diagonal
// texels, so the pair is coupled exactly like a quad tile: equal harmonic enrichments.
TEST(HarmonicEnrichment, Tri6PairBlockCouplesAcrossTheHypotenuse) {
  const int t = 32;
  const TexelTile tri = kernels::make_element_tile(ElementType::tri6, t);
  const std::vector<PlacedTile> pair = {{&tri, 0, 0, 0, false}, {&tri, 0, 0, 2, false}};
  TexelTile block = assemble_tile_block(pair, t, t);
  for (auto f : block.flags) ASSERT_FALSE(f & kernels::inactive);
  TexelTile square(t, t);
  const std::vector<kernels::TexelPoint> polyline = {{3.0, 25.0}, {20.5, 18.2}, {24.0, 6.0}};
  const auto cut_block = kernels::rasterize_cut(polyline, block);
  const auto cut_square = kernels::rasterize_cut(polyline, square);
  const HarmonicEnrichment h_block = harmonic_enrichment(block, cut_block);
  const HarmonicEnrichment h_square = harmonic_enrichment(square, cut_square);
  for (std::size_t k = 0; k < square.values.size(); ++k) ASSERT_NEAR(h_block.tile.values[k], h_square.tile.values[k], 1e-12);
  // Each triangle reads its half back; the diagonal texels agree in both.
  const TexelTile lower = extract_tile(h_block.tile, pair[0]), upper = extract_tile(h_block.tile, pair[1]);
  for (int i = 0; i < t; ++i) {
    const int j = t - 1 - i;  // diagonal texel (i, j) of the lower triangle is (t-1-i, t-1-j) of the upper one
    ASSERT_EQ(lower.values[lower.index(i, j)], upper.values[upper.index(t - 1 - i, t - 1 - j)]);
  }
  for (std::size_t k = 0; k < tri.flags.size(); ++k) {
    if (tri.flags[k] & kernels::inactive) {
      ASSERT_EQ(lower.values[k], 0.0);
    }
  }
}

TEST(HarmonicEnrichment, BlockPlacementErrors) {
  const TexelTile tile(8, 8);
  EXPECT_THROW(assemble_tile_block({{&tile, 4, 0, 0, false}}, 8, 8), std::invalid_argument);
  EXPECT_THROW(assemble_tile_block({{&tile, 0, 0, 9, false}}, 8, 8), std::invalid_argument);
  EXPECT_THROW(assemble_tile_block({{nullptr, 0, 0, 0, false}}, 8, 8), std::invalid_argument);
  TexelTile big(8, 8), small(4, 4);
  const auto cut = kernels::rasterize_cut({{0, 4}, {8, 4}}, big);
  EXPECT_THROW(harmonic_enrichment(small, cut), std::invalid_argument);
}
