// Cut rasterisation onto texel edges: exact lattice paths for lines along the lattice,
// through lattice points and along the border, direction independence, reference vs
// parallel (bitwise, any thread count) and the degenerate cases of issue 3.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>
#include <tuple>

#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/flood_fill.h"
#include "thread_count_support.h"

using namespace dgtex::kernels;

namespace {

int count_walls(const TexelTile& tile) {
  int n = 0;
  for (auto f : tile.flags) n += ((f & wall_east) != 0) + ((f & wall_north) != 0);
  return n;
}

std::vector<int> component_sizes(const TexelTile& tile) {
  std::vector<int> labels;
  const int count = label_components_reference(tile, labels);
  std::vector<int> sizes(count, 0);
  for (int l : labels)
    if (l >= 0) ++sizes[l];
  std::sort(sizes.begin(), sizes.end());
  return sizes;
}

// Undirected edge key: lower-left lattice point and axis.
std::set<std::tuple<int, int, int>> undirected_edges(const CutRaster& raster) {
  std::set<std::tuple<int, int, int>> keys;
  for (const auto& e : raster.edges)
    keys.insert({std::min(e.x, e.x + e.dx), std::min(e.y, e.y + e.dy), e.dx != 0 ? 0 : 1});
  return keys;
}

bool same_edges(const CutRaster& a, const CutRaster& b) {
  if (a.edges.size() != b.edges.size()) return false;
  for (std::size_t k = 0; k < a.edges.size(); ++k) {
    const auto &p = a.edges[k], &q = b.edges[k];
    if (std::tie(p.x, p.y, p.dx, p.dy, p.left_texel, p.right_texel) !=
        std::tie(q.x, q.y, q.dx, q.dy, q.left_texel, q.right_texel))
      return false;
  }
  return true;
}

}  // namespace

TEST(CutRasterization, SegmentAlongLatticeLineIsExact) {
  TexelTile tile(8, 8);
  const CutRaster raster = rasterize_cut({{1, 4}, {6, 4}}, tile);
  ASSERT_EQ(raster.edges.size(), 5u);
  for (int k = 0; k < 5; ++k) {
    const auto& e = raster.edges[k];
    EXPECT_EQ(e.x, 1 + k);
    EXPECT_EQ(e.y, 4);
    EXPECT_EQ(e.dx, 1);
    EXPECT_EQ(e.dy, 0);
    EXPECT_EQ(e.left_texel, tile.index(1 + k, 4));  // left of +x is above
    EXPECT_EQ(e.right_texel, tile.index(1 + k, 3));
    EXPECT_TRUE(tile.is_wall_north(1 + k, 3));
  }
  EXPECT_EQ(count_walls(tile), 5);
  EXPECT_EQ(raster.interior_edge_count(), 5);
}

TEST(CutRasterization, SidesFollowTheDirection) {
  TexelTile tile(8, 8);
  const CutRaster down = rasterize_cut({{3, 6}, {3, 5}}, tile);  // one step -y: left is east
  ASSERT_EQ(down.edges.size(), 1u);
  EXPECT_EQ(down.edges[0].left_texel, tile.index(3, 5));
  EXPECT_EQ(down.edges[0].right_texel, tile.index(2, 5));
  EXPECT_TRUE(tile.is_wall_east(2, 5));
  const CutRaster west = rasterize_cut({{5, 2}, {4, 2}}, tile);  // one step -x: left is below
  ASSERT_EQ(west.edges.size(), 1u);
  EXPECT_EQ(west.edges[0].left_texel, tile.index(4, 1));
  EXPECT_EQ(west.edges[0].right_texel, tile.index(4, 2));
}

TEST(CutRasterization, DiagonalThroughLatticePointsIsAStaircaseThroughThem) {
  TexelTile tile(16, 16);
  const CutRaster raster = rasterize_cut({{0, 0}, {16, 16}}, tile);
  ASSERT_EQ(raster.edges.size(), 32u);
  for (int k = 0; k <= 16; ++k) {
    const auto& e = raster.edges[std::min(2 * k, 31)];
    if (k < 16) {
      EXPECT_EQ(e.x, k);
      EXPECT_EQ(e.y, k);
    }
  }
  // Corner to corner: a complete cut into the two staircase halves (120 + 136 texels).
  EXPECT_EQ(component_sizes(tile), (std::vector<int>{120, 136}));
}

TEST(CutRasterization, ReversedPolylineGivesTheSameEdges) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> coord(-2.0, 34.0);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<TexelPoint> line(2 + trial % 5);
    for (auto& p : line) p = {coord(rng), coord(rng)};
    if (trial % 3 == 0) line[1] = {std::round(line[1][0]), std::round(line[1][1])};
    TexelTile a(32, 32), b(32, 32);
    const CutRaster forward = rasterize_cut(line, a);
    std::reverse(line.begin(), line.end());
    const CutRaster backward = rasterize_cut(line, b);
    ASSERT_EQ(a.flags, b.flags) << "trial " << trial;
    ASSERT_EQ(undirected_edges(forward), undirected_edges(backward)) << "trial " << trial;
    ASSERT_EQ(forward.edges.size(), backward.edges.size());
    for (std::size_t k = 0; k < forward.edges.size(); ++k) {  // reversed order, swapped sides
      const auto& f = forward.edges[k];
      const auto& r = backward.edges[forward.edges.size() - 1 - k];
      ASSERT_EQ(f.left_texel, r.right_texel);
      ASSERT_EQ(f.right_texel, r.left_texel);
    }
  }
}

TEST(CutRasterization, PathIsConnectedAndStaysNearTheSegment) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> coord(0.0, 64.0);
  for (int trial = 0; trial < 200; ++trial) {
    const TexelPoint p = {coord(rng), coord(rng)}, q = {coord(rng), coord(rng)};
    TexelTile tile(64, 64);
    const CutRaster raster = rasterize_cut({p, q}, tile);
    const double length = std::hypot(q[0] - p[0], q[1] - p[1]);
    for (std::size_t k = 0; k < raster.edges.size(); ++k) {
      const auto& e = raster.edges[k];
      ASSERT_EQ(std::abs(e.dx) + std::abs(e.dy), 1);
      if (k > 0) {  // 4-connected: each step starts where the last one ended
        ASSERT_EQ(e.x, raster.edges[k - 1].x + raster.edges[k - 1].dx);
        ASSERT_EQ(e.y, raster.edges[k - 1].y + raster.edges[k - 1].dy);
      }
      // Every lattice point of the path is within one texel of the segment's line.
      const double distance = std::abs((q[0] - p[0]) * (e.y - p[1]) - (q[1] - p[1]) * (e.x - p[0])) / length;
      ASSERT_LE(distance, 1.0) << "trial " << trial;
    }
  }
}

TEST(CutRasterization, ParallelMatchesReferenceBitwiseForAnyThreadCount) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> coord(-10.0, 138.0);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<TexelPoint> line(trial % 2 ? 50 : 300);  // serial and threaded paths
    for (auto& p : line) p = {coord(rng), coord(rng)};
    TexelTile ref_tile(128, 128);
    const CutRaster ref = rasterize_cut_reference(line, ref_tile);
    for (int threads : {1, 2, 4}) {
      const dgtex::test::ThreadCountGuard set_threads(threads);
      TexelTile tile(128, 128);
      const CutRaster par = rasterize_cut(line, tile, Execution::parallel);
      ASSERT_TRUE(same_edges(ref, par)) << "trial " << trial << " threads " << threads;
      ASSERT_EQ(ref_tile.flags, tile.flags);
    }
  }
}

TEST(CutRasterization, CutAlongElementEdgeSetsNoWalls) {
  TexelTile tile(8, 8);
  const CutRaster raster = rasterize_cut({{0, 0}, {8, 0}}, tile);
  ASSERT_EQ(raster.edges.size(), 8u);
  EXPECT_EQ(raster.interior_edge_count(), 0);
  EXPECT_EQ(count_walls(tile), 0);
  for (int k = 0; k < 8; ++k) {
    EXPECT_EQ(raster.edges[k].left_texel, tile.index(k, 0));
    EXPECT_EQ(raster.edges[k].right_texel, -1);
  }
}

TEST(CutRasterization, CutThroughMidsideNodeAndCornerNodes) {
  TexelTile through_midside(8, 8);
  rasterize_cut({{4, 0}, {4, 8}}, through_midside);  // quad8 midside nodes 4 and 6
  EXPECT_EQ(component_sizes(through_midside), (std::vector<int>{32, 32}));
  TexelTile through_corners(8, 8);
  rasterize_cut({{8, 0}, {0, 8}}, through_corners);  // corner nodes 1 and 3
  const auto sizes = component_sizes(through_corners);
  ASSERT_EQ(sizes.size(), 2u);
  EXPECT_EQ(sizes[0] + sizes[1], 64);
  EXPECT_EQ(sizes[0], 28);  // the staircase keeps the diagonal texels with one side
}

TEST(CutRasterization, CutEndingExactlyOnTheBoundaryIsComplete) {
  TexelTile tile(16, 16);
  const CutRaster raster = rasterize_cut({{0, 5.3}, {7.6, 9.2}, {16.0, 12.0}}, tile);
  EXPECT_EQ(raster.edges.back().x + raster.edges.back().dx, 16);
  EXPECT_EQ(raster.edges.back().y + raster.edges.back().dy, 12);
  EXPECT_EQ(component_sizes(tile).size(), 2u);
}

TEST(CutRasterization, PolylineIsClippedToTheTile) {
  TexelTile tile(8, 8);
  const CutRaster raster = rasterize_cut({{-3.0, 3.0}, {11.0, 3.0}}, tile);
  ASSERT_EQ(raster.edges.size(), 8u);
  EXPECT_EQ(raster.edges.front().x, 0);
  EXPECT_EQ(raster.edges.back().x, 7);
  EXPECT_EQ(component_sizes(tile), (std::vector<int>{24, 40}));
  TexelTile outside(8, 8);
  EXPECT_TRUE(rasterize_cut({{-3.0, -1.0}, {-1.0, 20.0}}, outside).edges.empty());
}

TEST(CutRasterization, FragmentsOfAFewTexels) {
  TexelTile tile(16, 16);
  EXPECT_TRUE(rasterize_cut({{3.2, 3.2}, {3.4, 3.3}}, tile).edges.empty());  // shorter than half a texel
  EXPECT_EQ(count_walls(tile), 0);
  const CutRaster one = rasterize_cut({{3.2, 3.1}, {4.4, 3.3}}, tile);
  ASSERT_EQ(one.edges.size(), 1u);
  EXPECT_TRUE(tile.is_wall_north(3, 2));
  const CutRaster three = rasterize_cut({{8.1, 7.9}, {8.0, 11.1}}, tile);
  EXPECT_EQ(three.edges.size(), 3u);
  EXPECT_EQ(component_sizes(tile).size(), 1u);  // fragments do not split anything
}

TEST(CutRasterization, SelfIntersectingCutEnclosesALoop) {
  TexelTile tile(8, 8);
  // Crosses itself at (4, 2): the loop [4,6] x [2,6] encloses 8 texels.
  const CutRaster raster = rasterize_cut({{2, 2}, {6, 2}, {6, 6}, {4, 6}, {4, 0}}, tile);
  EXPECT_EQ(raster.edges.size(), 4u + 4u + 2u + 6u);
  EXPECT_EQ(component_sizes(tile), (std::vector<int>{8, 56}));
}

TEST(CutRasterization, RetracedCutKeepsEveryTraversal) {
  TexelTile tile(8, 8);
  const CutRaster raster = rasterize_cut({{1, 4}, {5, 4}, {2, 4}}, tile);
  EXPECT_EQ(raster.edges.size(), 7u);
  EXPECT_EQ(count_walls(tile), 4);
}

TEST(CutRasterization, Tri6HypotenuseFollowsTheActiveBoundary) {
  const int t = 16;
  TexelTile tile = make_element_tile(ElementType::tri6, t);
  int active = 0;
  for (auto f : tile.flags) active += !(f & inactive);
  EXPECT_EQ(active, t * (t + 1) / 2);
  for (const auto& line : {std::vector<TexelPoint>{{0, 16}, {16, 0}}, std::vector<TexelPoint>{{16, 0}, {0, 16}}}) {
    TexelTile cut = tile;
    const CutRaster raster = rasterize_cut(line, cut);
    ASSERT_EQ(raster.edges.size(), 2u * t);
    EXPECT_EQ(raster.interior_edge_count(), 0);
    for (const auto& e : raster.edges) EXPECT_TRUE((e.left_texel >= 0) != (e.right_texel >= 0));
    EXPECT_EQ(component_sizes(cut), (std::vector<int>{active}));
  }
}

// The same hypotenuse with the round-off a surface projection leaves (ends and an
// intermediate point off the line by 1e-13 texels, both ways): still the outer staircase.
// With an exact tie test the path wandered to the inner side of some diagonal texels.
TEST(CutRasterization, Tri6HypotenuseWithRoundOffFollowsTheActiveBoundary) {
  const int t = 16;
  const TexelTile tile = make_element_tile(ElementType::tri6, t);
  for (double eps : {1e-13, -1e-13}) {
    const std::vector<TexelPoint> line{{16 - eps, eps}, {8 + eps, 8 + eps}, {eps, 16 - 2 * eps}};
    TexelTile cut = tile;
    const CutRaster raster = rasterize_cut(line, cut);
    ASSERT_EQ(raster.edges.size(), 2u * t);
    EXPECT_EQ(raster.interior_edge_count(), 0) << "eps " << eps;
    for (const auto& e : raster.edges) EXPECT_TRUE((e.left_texel >= 0) != (e.right_texel >= 0)) << "eps " << eps;
  }
}

TEST(CutRasterization, ParametricMapsRoundTrip) {
  for (ElementType type : {ElementType::quad8, ElementType::tri6}) {
    const TexelPoint p = texel_point_from_parametric(type, 64, 0.25, 0.5);
    const auto xi = parametric_from_texel_point(type, 64, p);
    EXPECT_DOUBLE_EQ(xi[0], 0.25);
    EXPECT_DOUBLE_EQ(xi[1], 0.5);
  }
  EXPECT_EQ(texel_point_from_parametric(ElementType::quad8, 64, -1, 1), (TexelPoint{0, 64}));
  EXPECT_EQ(texel_point_from_parametric(ElementType::tri6, 64, 1, 0), (TexelPoint{64, 0}));
}

namespace {
std::vector<std::size_t> piece_sizes(const std::vector<TexelPoint>& earlier, const std::vector<TexelPoint>& later) {
  TexelTile walls(32, 32), scratch(32, 32);
  rasterize_cut(earlier, walls);
  const auto pieces = split_cut_at_crossings(rasterize_cut(later, scratch), walls);
  std::vector<std::size_t> sizes;
  for (const auto& p : pieces) sizes.push_back(p.edges.size());
  return sizes;
}
}  // namespace

TEST(CutRasterization, SplitWhereTheCutMeetsEarlierCutsOrTheBoundary) {
  const std::vector<TexelPoint> horizontal = {{0, 16}, {32, 16}};
  using Sizes = std::vector<std::size_t>;
  EXPECT_EQ(piece_sizes(horizontal, {{16, 0}, {16, 32}}), (Sizes{16, 16}));         // X crossing
  EXPECT_EQ(piece_sizes(horizontal, {{16, 32}, {16, 0}}), (Sizes{16, 16}));         // either direction
  EXPECT_EQ(piece_sizes(horizontal, {{3, 2.2}, {29, 30.1}}).size(), 2u);             // slanted crossing
  EXPECT_EQ(piece_sizes(horizontal, {{16, 0}, {16, 16}}), (Sizes{16}));             // T-junction
  EXPECT_EQ(piece_sizes(horizontal, {{16, 0}, {16, 16}, {20, 16}}), (Sizes{20}));   // ends along it
  EXPECT_EQ(piece_sizes(horizontal, {{4, 0}, {12, 16}, {20, 16}, {28, 0}}).size(), 2u);  // touches and turns back
  EXPECT_EQ(piece_sizes(horizontal, {{10, 0}, {10, 16}, {14, 16}, {14, 32}}), (Sizes{16, 20}));  // crosses along it
  EXPECT_EQ(piece_sizes(horizontal, {{2, 2}, {9, 5}}), (Sizes{10}));                // no contact
  // Touching the element boundary mid-way splits too; starting or ending there does not.
  EXPECT_EQ(piece_sizes({{0, 0}, {0, 1}}, {{4, 0}, {16, 32}, {28, 0}}).size(), 2u);
  EXPECT_EQ(piece_sizes({{0, 0}, {0, 1}}, {{0, 4}, {32, 20}}).size(), 1u);
  // A staircase crossing a staircase: split once.
  EXPECT_EQ(piece_sizes({{0, 0}, {32, 32}}, {{0, 32}, {32, 0}}).size(), 2u);
}

TEST(CutRasterization, InvalidInputIsAnError) {
  TexelTile tile(8, 8);
  EXPECT_THROW(rasterize_cut({{1, 1}}, tile), std::invalid_argument);
  EXPECT_THROW(rasterize_cut({{1, 1}, {std::numeric_limits<double>::quiet_NaN(), 2}}, tile), std::invalid_argument);
  EXPECT_THROW(make_element_tile(ElementType::quad8, 48), std::invalid_argument);
}
