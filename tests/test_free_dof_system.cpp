// FreeDofSystem's compressed lower triangle against the layout written out plainly: every
// (free row, free column) entry of the pattern's blocks at or below the diagonal, sorted by
// column and then row. Checked on a pattern of overlapping sources with unused slots, with
// fixed DOFs and with a kept-blocks mask (the element-local preconditioner's form), through
// the index arrays and through gather.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <tuple>
#include <vector>

#include "dgtex/block_assembly.h"
#include "dgtex/free_dof_system.h"

using namespace dgtex;

namespace {

// Sources of 6 nodes over a strip of nodes, each overlapping the next by 3, with some slots
// unused; a second family couples pairs of distant nodes (as edges and virtual nodes do).
BlockAssembly strip_pattern(int nodes) {
  BlockSourceFamily elements{0, 6, {}, {}};
  for (int first = 0; first + 6 <= nodes; first += 3) {
    for (int a = 0; a < 6; ++a) elements.global_nodes.push_back((first + a) % 5 == 4 ? -1 : first + a);
    ++elements.count;
  }
  BlockSourceFamily pairs{0, 2, {}, {}};
  for (int a = 0; a + nodes / 2 < nodes; a += 4) {
    pairs.global_nodes.push_back(a);
    pairs.global_nodes.push_back(a + nodes / 2);
    ++pairs.count;
  }
  return BlockAssembly(nodes, {elements, pairs});
}

struct Entry {
  int column, row;
  std::int64_t source;
};

std::vector<Entry> reference_entries(const BlockAssembly& pattern, const std::vector<char>& fixed,
                                     const std::vector<char>* kept) {
  std::vector<int> unknown(fixed.size(), -1);
  int count = 0;
  for (size_t d = 0; d < fixed.size(); ++d)
    if (!fixed[d]) unknown[d] = count++;
  std::vector<Entry> entries;
  for (int row = 0; row < pattern.num_nodes(); ++row)
    for (std::int64_t k = pattern.row_start()[row]; k < pattern.row_start()[row + 1]; ++k) {
      if (kept && !(*kept)[k]) continue;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
          const int ur = unknown[3 * row + r], uc = unknown[3 * pattern.column()[k] + c];
          if (ur >= 0 && uc >= 0 && ur >= uc) entries.push_back({uc, ur, k * 9 + r * 3 + c});
        }
    }
  std::sort(entries.begin(), entries.end(),
            [](const Entry& a, const Entry& b) { return std::tie(a.column, a.row) < std::tie(b.column, b.row); });
  return entries;
}

void expect_layout(const BlockAssembly& pattern, const std::vector<char>& fixed, const std::vector<char>* kept) {
  const FreeDofSystem system(pattern, fixed, kept);
  const std::vector<Entry> expected = reference_entries(pattern, fixed, kept);
  ASSERT_EQ(system.nonzeros(), static_cast<std::int64_t>(expected.size()));
  std::vector<int> column_start(system.size() + 1, 0);
  for (const Entry& e : expected) ++column_start[e.column + 1];
  for (int j = 0; j < system.size(); ++j) column_start[j + 1] += column_start[j];
  EXPECT_EQ(system.column_start(), column_start);
  // Values that name their block entry: gather must read each slot's own entry.
  std::vector<double> a(static_cast<size_t>(pattern.num_blocks()) * 9);
  for (size_t i = 0; i < a.size(); ++i) a[i] = static_cast<double>(i);
  std::vector<double> values;
  system.gather(a.data(), 1.0, nullptr, 0.0, values);
  for (size_t s = 0; s < expected.size(); ++s) {
    EXPECT_EQ(system.row_index()[s], expected[s].row) << "slot " << s;
    EXPECT_EQ(values[s], static_cast<double>(expected[s].source)) << "slot " << s;
  }
}

}  // namespace

TEST(FreeDofSystem, LowerTriangleMatchesThePlainLayout) {
  const BlockAssembly pattern = strip_pattern(40);
  ASSERT_GT(pattern.num_blocks(), 200);
  std::mt19937 rng(7);
  std::vector<char> none(3 * 40, 0), some(3 * 40, 0);
  for (char& f : some) f = rng() % 4 == 0;
  std::vector<char> kept(static_cast<size_t>(pattern.num_blocks()));
  for (char& k : kept) k = rng() % 3 != 0;
  expect_layout(pattern, none, nullptr);
  expect_layout(pattern, some, nullptr);
  expect_layout(pattern, some, &kept);
}
