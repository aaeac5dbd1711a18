// Flood fill of texel components: the parallel union-find form against the BFS reference
// (bitwise, thread counts 1, 2, 4) on random wall and inactive patterns with fixed seeds,
// the canonical numbering, and small configurations with known answers.
#include <gtest/gtest.h>
#include <omp.h>

#include <random>

#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/flood_fill.h"
#include "dgtex/kernels/multigrid_unknowns.h"
#include "thread_count_support.h"

using namespace dgtex::kernels;

namespace {

TexelTile random_tile(int w, int h, double wall_probability, double inactive_probability, unsigned seed) {
  std::mt19937 rng(seed);
  std::bernoulli_distribution wall(wall_probability), off(inactive_probability);
  TexelTile tile(w, h);
  for (auto& f : tile.flags)
    f = static_cast<std::uint8_t>((wall(rng) ? wall_east : 0) | (wall(rng) ? wall_north : 0) | (off(rng) ? inactive : 0));
  return tile;
}

}  // namespace

TEST(FloodFill, ParallelMatchesReferenceOnRandomWalls) {
  unsigned seed = 1;
  for (int size : {1, 7, 64, 256})
    for (double p : {0.0, 0.2, 0.45, 0.6, 0.9})
      for (double q : {0.0, 0.1}) {
        const TexelTile tile = random_tile(size, size == 7 ? 13 : size, p, q, seed++);
        std::vector<int> reference;
        const int count = label_components_reference(tile, reference);
        std::vector<int> serial;
        ASSERT_EQ(label_components(tile, serial, Execution::serial), count);
        ASSERT_EQ(serial, reference);
        for (int threads : {1, 2, 4}) {
          const dgtex::test::ThreadCountGuard set_threads(threads);
          std::vector<int> parallel;
          ASSERT_EQ(label_components(tile, parallel), count) << "size " << size << " p " << p << " threads " << threads;
          ASSERT_EQ(parallel, reference) << "size " << size << " p " << p << " threads " << threads;
        }
      }
}

TEST(FloodFill, LabelsAreNumberedByTheirSmallestTexel) {
  const TexelTile tile = random_tile(64, 64, 0.5, 0.05, 99);
  std::vector<int> labels;
  const int count = label_components(tile, labels);
  int next = 0;
  for (std::size_t t = 0; t < labels.size(); ++t) {
    if (tile.flags[t] & inactive) {
      ASSERT_EQ(labels[t], -1);
      continue;
    }
    ASSERT_LE(labels[t], next);  // a new label appears first at its smallest texel
    if (labels[t] == next) ++next;
  }
  EXPECT_EQ(next, count);
  // Labels are constant across every uncut link and are the only thing the BFS sees.
  for (int j = 0; j < 64; ++j)
    for (int i = 0; i < 64; ++i) {
      if (texels_coupled_east(tile, i, j)) {
        ASSERT_EQ(labels[tile.index(i, j)], labels[tile.index(i + 1, j)]);
      }
      if (texels_coupled_north(tile, i, j)) {
        ASSERT_EQ(labels[tile.index(i, j)], labels[tile.index(i, j + 1)]);
      }
    }
}

TEST(FloodFill, KnownConfigurations) {
  TexelTile open(16, 16);
  std::vector<int> labels;
  EXPECT_EQ(label_components(open, labels), 1);

  TexelTile split(16, 16);
  rasterize_cut({{5, 0}, {5, 16}}, split);
  EXPECT_EQ(label_components(split, labels), 2);
  EXPECT_EQ(labels[split.index(4, 9)], 0);
  EXPECT_EQ(labels[split.index(5, 9)], 1);

  // A serpentine: walls leave one long corridor (worst case for label propagation).
  TexelTile snake(32, 32);
  for (int j = 0; j + 1 < 32; ++j)
    for (int i = 0; i < 32; ++i)
      if ((j % 2 == 0) ? i != 31 : i != 0) snake.flags[snake.index(i, j)] |= wall_north;
  EXPECT_EQ(label_components(snake, labels), 1);
  std::vector<int> reference;
  EXPECT_EQ(label_components_reference(snake, reference), 1);

  // Isolated texels: every link cut.
  TexelTile dust(8, 8);
  for (auto& f : dust.flags) f = wall_east | wall_north;
  EXPECT_EQ(label_components(dust, labels), 64);
  for (int t = 0; t < 64; ++t) EXPECT_EQ(labels[t], t);

  // tri6: inactive half labelled -1, the triangle is one component.
  const TexelTile tri = make_element_tile(dgtex::kernels::ElementType::tri6, 16);
  EXPECT_EQ(label_components(tri, labels), 1);
  EXPECT_EQ(labels[tri.index(15, 15)], -1);
  EXPECT_EQ(labels[tri.index(15, 0)], 0);
}

TEST(FloodFill, MalformedTileIsAnError) {
  TexelTile bad(4, 4);
  bad.flags.resize(3);
  std::vector<int> labels;
  EXPECT_THROW(label_components(bad, labels), std::invalid_argument);
  EXPECT_THROW(label_components_reference(bad, labels), std::invalid_argument);
}
