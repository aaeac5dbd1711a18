// Complete cuts (thesis §5.4.1-5.4.2, App. A.2): the generalized Heaviside is exactly +-1
// per side, the harmonic enrichment of a complete cut equals it (exactly through the
// constant-component rule, and to solver accuracy through a plain CHOLMOD solve), and
// the canonical Heavisides are the component indicators.
#include <gtest/gtest.h>

#include <cmath>

#include "dgtex/harmonic_enrichment.h"
#include "dgtex/heaviside.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/laplace_direct.h"

using namespace dgtex;
using kernels::ElementType;
using kernels::TexelTile;

TEST(Heaviside, SingleCompleteCutIsPlusMinusOne) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const int t = 64;
    TexelTile tile = kernels::make_element_tile(type, t);
    // A wavy cut from the left edge to the bottom edge (both element edges for either type).
    const auto cut = kernels::rasterize_cut({{0.0, 40.3}, {10.2, 30.1}, {17.7, 31.4}, {25.5, 12.2}, {30.2, 0.0}}, tile);
    ASSERT_TRUE(is_complete_cut(tile, cut));
    const TexelTile h = complete_cut_heaviside(tile, cut);
    int plus = 0, minus = 0;
    for (std::size_t k = 0; k < h.values.size(); ++k) {
      if (tile.flags[k] & kernels::inactive) {
        ASSERT_EQ(h.values[k], 0.0);
        continue;
      }
      ASSERT_TRUE(h.values[k] == 1.0 || h.values[k] == -1.0);
      (h.values[k] > 0 ? plus : minus)++;
    }
    EXPECT_EQ(h.values[tile.index(0, 0)], -1.0);  // the cut runs down-right: (0,0) is on its right
    EXPECT_EQ(h.values[tile.index(40, 10)], 1.0);  // left of the cut
    EXPECT_GT(plus, 0);
    EXPECT_GT(minus, 0);

    // The harmonic enrichment of a complete cut is the same function, exactly.
    const HarmonicEnrichment harmonic = harmonic_enrichment(tile, cut);
    EXPECT_EQ(harmonic.tile.values, h.values);
    EXPECT_EQ(harmonic.solved_components, 0);
    EXPECT_EQ(harmonic.constant_components, 2);
    // A plain CHOLMOD solve of the same Dirichlet problem agrees to solver accuracy.
    TexelTile direct = tile;
    set_cut_dirichlet(direct, cut);
    solve_laplace_direct(direct);
    for (std::size_t k = 0; k < h.values.size(); ++k) ASSERT_NEAR(direct.values[k], h.values[k], 1e-10);
  }
}

TEST(Heaviside, CanonicalHeavisidesAreComponentIndicators) {
  TexelTile tile(32, 32);
  kernels::rasterize_cut({{0, 16}, {32, 16}}, tile);
  kernels::rasterize_cut({{10, 0}, {10, 16}}, tile);   // ends on the first cut: 3 components
  kernels::rasterize_cut({{20, 32}, {20.4, 16}}, tile);  // and a fourth
  const auto indicators = canonical_heavisides(tile);
  ASSERT_EQ(indicators.size(), 4u);
  for (std::size_t k = 0; k < tile.values.size(); ++k) {
    double sum = 0;
    for (const auto& h : indicators) {
      ASSERT_TRUE(h.values[k] == 0.0 || h.values[k] == 1.0);
      sum += h.values[k];
    }
    ASSERT_EQ(sum, 1.0);
  }
  EXPECT_EQ(indicators[0].values[tile.index(0, 0)], 1.0);    // component of texel 0 comes first
  EXPECT_EQ(indicators[1].values[tile.index(10, 0)], 1.0);
}

TEST(Heaviside, PartialCutIsRejected) {
  TexelTile tile(32, 32);
  const auto cut = kernels::rasterize_cut({{0, 16}, {16, 16}}, tile);
  EXPECT_FALSE(is_complete_cut(tile, cut));
  EXPECT_THROW(complete_cut_heaviside(tile, cut), std::invalid_argument);
}

TEST(Heaviside, CutAlongTheElementEdgeIsNotComplete) {
  TexelTile tile(16, 16);
  const auto cut = kernels::rasterize_cut({{16, 0}, {16, 16}}, tile);
  EXPECT_FALSE(is_complete_cut(tile, cut));  // only one side lies in this element
  const TexelTile h = complete_cut_heaviside(tile, cut);
  for (double v : h.values) ASSERT_EQ(v, 1.0);  // constant: the neighbour holds the other side
}

TEST(Heaviside, ComponentsTheCutDoesNotTouchAreZero) {
  TexelTile tile(32, 32);
  const auto first = kernels::rasterize_cut({{0, 16}, {32, 16}}, tile);
  kernels::rasterize_cut({{8, 16}, {8, 32}}, tile);  // splits the upper half
  const auto second = kernels::rasterize_cut({{20, 0}, {20, 16}}, tile);  // splits the lower half
  const TexelTile h2 = complete_cut_heaviside(tile, second);
  EXPECT_EQ(h2.values[tile.index(2, 30)], 0.0);
  EXPECT_EQ(h2.values[tile.index(25, 30)], 0.0);
  EXPECT_EQ(h2.values[tile.index(2, 2)], 1.0);  // the cut goes up: west is its left
  EXPECT_EQ(h2.values[tile.index(25, 2)], -1.0);
  // The first cut's Heaviside sees the other cuts as Neumann walls only: still +-1.
  const TexelTile h1 = complete_cut_heaviside(tile, first);
  EXPECT_EQ(h1.values[tile.index(2, 30)], 1.0);
  EXPECT_EQ(h1.values[tile.index(25, 30)], 1.0);
  EXPECT_EQ(h1.values[tile.index(2, 2)], -1.0);
}
