// FreeDofSystem's compressed lower triangle against the layout written out plainly: every
// (free row, free column) entry of the pattern's blocks at or below the diagonal, sorted by
// column and then row. Checked on a pattern of overlapping sources with unused slots, with
// fixed DOFs and with a kept-blocks mask (the element-local preconditioner's form), through
// the index arrays and through gather.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <random>
#include <stdexcept>
#include <string>
#include <tuple>
#include <vector>

#include "dgtex/block_assembly.h"
#include "dgtex/free_dof_system.h"
#include "shell_test_support.h"

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

// With dependent nodes, x = T x_free: the system is T^T A T over the DOFs that are neither
// fixed nor dependent, restrict_vector is T^T, expand_vector T; collect and distribute apply
// them in place over all DOFs. All against T and A written out densely, on the strip with
// fixed DOFs, three dependent nodes (one with a fixed DOF, one following a node with a fixed
// DOF) and new couplings (a source far from its dependent node's neighbours).
TEST(FreeDofSystem, DependentNodesGiveTheSystemOfTTransposeATimesT) {
  const int nodes = 40, n = 3 * nodes;
  const BlockAssembly pattern = strip_pattern(nodes);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> uniform(-1, 1);
  std::vector<char> fixed(n, 0);
  fixed[3 * 0 + 0] = fixed[3 * 0 + 1] = fixed[3 * 0 + 2] = 1;
  fixed[3 * 9 + 2] = 1;   // a DOF of a source
  fixed[3 * 21 + 1] = 1;  // a DOF of a dependent node: stays fixed
  const std::vector<DependentNode> dependents = {
      {21, {{20, 0.5}, {9, -1.25}, {35, 2.0}}}, {5, {{4, 1.0}, {6, -1.0}}}, {30, {{1, 0.75}}}};
  const FreeDofSystem system(pattern, fixed, nullptr, &dependents);

  // Dense A (symmetric over the pattern's blocks) and T.
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(n, n);
  for (int r = 0; r < nodes; ++r)
    for (std::int64_t k = pattern.row_start()[r]; k < pattern.row_start()[r + 1]; ++k) {
      const int c = pattern.column()[k];
      if (c > r) continue;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) dense(3 * r + i, 3 * c + j) = dense(3 * c + j, 3 * r + i) = uniform(rng);
    }
  std::vector<double> blocks(static_cast<size_t>(pattern.num_blocks()) * 9);
  for (int r = 0; r < nodes; ++r)
    for (std::int64_t k = pattern.row_start()[r]; k < pattern.row_start()[r + 1]; ++k)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) blocks[9 * k + 3 * i + j] = dense(3 * r + i, 3 * pattern.column()[k] + j);
  std::vector<int> unknown(n, -1);  // the unknowns T numbers, in DOF order
  int count = 0;
  for (int d = 0; d < n; ++d)
    if (!fixed[d] && d / 3 != 21 && d / 3 != 5 && d / 3 != 30) unknown[d] = count++;
  ASSERT_EQ(system.size(), count);
  const Eigen::MatrixXd T = testing_support::dense_elimination_matrix(fixed, dependents);
  ASSERT_EQ(T.cols(), count);
  const Eigen::MatrixXd reduced = T.transpose() * dense * T;

  std::vector<double> values;
  system.gather(blocks.data(), 2.0, blocks.data(), -0.5, values);  // 1.5 A
  Eigen::MatrixXd gathered = Eigen::MatrixXd::Zero(count, count);
  for (int j = 0; j < count; ++j)
    for (int k = system.column_start()[j]; k < system.column_start()[j + 1]; ++k) {
      ASSERT_GE(system.row_index()[k], j);
      if (k > system.column_start()[j]) {
        ASSERT_GT(system.row_index()[k], system.row_index()[k - 1]);
      }
      gathered(system.row_index()[k], j) = gathered(j, system.row_index()[k]) = values[k];
    }
  EXPECT_LT((gathered - 1.5 * reduced).cwiseAbs().maxCoeff(), 1e-12 * reduced.cwiseAbs().maxCoeff());
  EXPECT_GT(system.nonzeros(), FreeDofSystem(pattern, fixed).nonzeros() / 2);  // new couplings, not fewer

  std::vector<double> full(n), reduced_x(count);
  for (double& x : full) x = uniform(rng);
  for (double& x : reduced_x) x = uniform(rng);
  const Eigen::Map<const Eigen::VectorXd> full_map(full.data(), n), reduced_map(reduced_x.data(), count);
  std::vector<double> restricted, expanded;
  system.restrict_vector(full, restricted);
  system.expand_vector(reduced_x, expanded);
  EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(restricted.data(), count) - T.transpose() * full_map).cwiseAbs().maxCoeff(), 1e-14);
  EXPECT_LT((Eigen::Map<const Eigen::VectorXd>(expanded.data(), n) - T * reduced_map).cwiseAbs().maxCoeff(), 1e-14);
  // collect: T^T in place (dependent entries zero, fixed ones as they were).
  std::vector<double> collected = full;
  system.collect(collected);
  std::vector<double> collected_restricted;
  system.restrict_vector(collected, collected_restricted);
  EXPECT_EQ(collected_restricted, restricted);
  for (int d = 0; d < n; ++d) {
    if (system.is_dependent(d)) {
      EXPECT_EQ(collected[d], 0.0) << "DOF " << d;
    }
    if (fixed[d]) {
      EXPECT_EQ(collected[d], full[d]) << "DOF " << d;
    }
  }
  EXPECT_FALSE(system.is_dependent(3 * 21 + 1));  // fixed
  EXPECT_TRUE(system.is_dependent(3 * 21 + 0));
  // distribute: the dependent entries of T x_free from the free entries alone.
  std::vector<double> distributed(n, 0.0);
  for (int d = 0; d < n; ++d)
    if (unknown[d] >= 0) distributed[d] = reduced_x[unknown[d]];
  system.distribute(distributed);
  EXPECT_EQ(distributed, expanded);
}

TEST(FreeDofSystem, DependentNodesThatCannotBeEliminatedAreRefused) {
  const BlockAssembly pattern = strip_pattern(12);
  const std::vector<char> fixed(36, 0);
  const auto refused = [&](std::vector<DependentNode> dependents, const std::string& expected) {
    try {
      FreeDofSystem(pattern, fixed, nullptr, &dependents);
      ADD_FAILURE() << "accepted; expected: " << expected;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused({{12, {{1, 1.0}}}}, "node 12 is out of range; expected 0..11");
  refused({{3, {{-1, 1.0}}}}, "source -1 is out of range");
  refused({{3, {{1, 1.0}}}, {3, {{2, 1.0}}}}, "node 3 is dependent twice");
  refused({{3, {{4, 1.0}}}, {4, {{2, 1.0}}}}, "node 3 follows node 4, which is dependent itself");
  refused({{3, {{1, 1.0}, {1, 2.0}}}}, "node 3 names a source twice");
}
