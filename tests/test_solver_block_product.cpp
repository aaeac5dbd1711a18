// The block products of the step and its PCG (dgtex/kernels/block_product.h): on every
// instruction-set path the machine supports they are bitwise their one-entry references
// (rows of 0 to 13 blocks, so every stream count and tail), the pair and the fused mass
// product are bitwise the single products, a row range writes only its rows, and the
// references agree with a plain dense product to round-off. The solver's A p (block and
// scalar mass) is bitwise the same on 1 and 2 threads.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "dgtex/block_assembly.h"
#include "dgtex/kernels/block_product.h"
#include "dgtex/shell_model.h"
#include "shell_test_support.h"
#include "vector_path_support.h"
#include "thread_count_support.h"

using namespace dgtex;
using dgtex::testing_support::random_values;

namespace {

// A random block-row pattern: row r has r % 14 blocks in distinct random columns.
struct RandomBlockMatrix {
  int nodes = 0;
  std::vector<std::int64_t> row_start{0};
  std::vector<int> column;
  std::vector<double> blocks, scalars;
  kernels::BlockRows rows() const { return {row_start.data(), column.data()}; }
};

RandomBlockMatrix random_block_matrix(int nodes, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  RandomBlockMatrix m;
  m.nodes = nodes;
  std::vector<int> all(nodes);
  for (int c = 0; c < nodes; ++c) all[c] = c;
  for (int r = 0; r < nodes; ++r) {
    std::shuffle(all.begin(), all.end(), rng);
    const int count = std::min(r % 14, nodes);
    m.column.insert(m.column.end(), all.begin(), all.begin() + count);
    m.row_start.push_back(static_cast<std::int64_t>(m.column.size()));
  }
  m.blocks.resize(9 * m.column.size());
  for (double& x : m.blocks) x = u(rng);
  m.scalars.resize(m.column.size());
  for (double& x : m.scalars) x = u(rng);
  return m;
}

std::vector<double> spread_of(const std::vector<double>& x) {
  std::vector<double> spread(3 * x.size());
  kernels::spread_block_vector(static_cast<std::int64_t>(x.size() / 3), x.data(), spread.data());
  return spread;
}

TEST(BlockProduct, EveryPathIsBitwiseTheReference) {
  const RandomBlockMatrix m = random_block_matrix(60, 3u);
  const std::vector<double> x = random_values(3 * m.nodes, 5u), x2 = random_values(3 * m.nodes, 7u);
  const std::vector<double> spread = spread_of(x), spread2 = spread_of(x2);
  const int n = 3 * m.nodes;
  std::vector<double> kx(n), kx2(n), sx(n);
  kernels::block_rows_product_reference(m.rows(), 0, m.nodes, m.blocks.data(), x.data(), kx.data());
  kernels::block_rows_product_reference(m.rows(), 0, m.nodes, m.blocks.data(), x2.data(), kx2.data());
  kernels::scalar_rows_product_reference(m.rows(), 0, m.nodes, m.scalars.data(), x.data(), sx.data());
  for (kernels::VectorPath path : testing_support::supported_vector_paths()) {
    SCOPED_TRACE("path " + std::to_string(static_cast<int>(path)));
    std::vector<double> y(n, 7.0), y2(n, 7.0), ys(n, 7.0);
    kernels::block_rows_product(m.rows(), 0, m.nodes, m.blocks.data(), spread.data(), y.data(), path);
    EXPECT_EQ(y, kx);
    std::fill(y.begin(), y.end(), 7.0);
    kernels::block_rows_product_pair(m.rows(), 0, m.nodes, m.blocks.data(), spread.data(), spread2.data(), y.data(),
                                     y2.data(), path);
    EXPECT_EQ(y, kx);
    EXPECT_EQ(y2, kx2);
    kernels::scalar_rows_product(m.rows(), 0, m.nodes, m.scalars.data(), spread.data(), ys.data(), path);
    EXPECT_EQ(ys, sx);
    std::fill(y.begin(), y.end(), 7.0);
    std::fill(ys.begin(), ys.end(), 7.0);
    kernels::block_and_scalar_rows_product(m.rows(), 0, m.nodes, m.blocks.data(), m.scalars.data(), spread.data(),
                                           y.data(), ys.data(), path);
    EXPECT_EQ(y, kx);
    EXPECT_EQ(ys, sx);
  }
}

TEST(BlockProduct, ARowRangeWritesOnlyItsRows) {
  const RandomBlockMatrix m = random_block_matrix(40, 9u);
  const std::vector<double> x = random_values(3 * m.nodes, 11u);
  const std::vector<double> spread = spread_of(x);
  std::vector<double> whole(3 * m.nodes), part(3 * m.nodes, -5.0);
  kernels::block_rows_product(m.rows(), 0, m.nodes, m.blocks.data(), spread.data(), whole.data());
  kernels::block_rows_product(m.rows(), 13, 29, m.blocks.data(), spread.data(), part.data());
  for (int d = 0; d < 3 * m.nodes; ++d) {
    if (d >= 3 * 13 && d < 3 * 29) EXPECT_EQ(part[d], whole[d]) << d;
    else EXPECT_EQ(part[d], -5.0) << d;
  }
}

TEST(BlockProduct, ReferencesAreTheDenseProductToRoundOff) {
  const RandomBlockMatrix m = random_block_matrix(50, 13u);
  const std::vector<double> x = random_values(3 * m.nodes, 17u);
  const int n = 3 * m.nodes;
  std::vector<double> kx(n), sx(n), dense_k(n, 0.0), dense_s(n, 0.0);
  kernels::block_rows_product_reference(m.rows(), 0, m.nodes, m.blocks.data(), x.data(), kx.data());
  kernels::scalar_rows_product_reference(m.rows(), 0, m.nodes, m.scalars.data(), x.data(), sx.data());
  for (int r = 0; r < m.nodes; ++r)
    for (std::int64_t k = m.row_start[r]; k < m.row_start[r + 1]; ++k)
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) dense_k[3 * r + i] += m.blocks[9 * k + 3 * i + j] * x[3 * m.column[k] + j];
        dense_s[3 * r + i] += m.scalars[k] * x[3 * m.column[k] + i];
      }
  for (int d = 0; d < n; ++d) {
    EXPECT_NEAR(kx[d], dense_k[d], 1e-13 * 40) << d;  // at most 13 blocks of 9 terms of size <= 1
    EXPECT_NEAR(sx[d], dense_s[d], 1e-13 * 15) << d;
  }
}

TEST(BlockProduct, BlockMultiplyIsTheReferenceOnOneAndTwoThreads) {
  // 400 sources of 10 random nodes each: ~40k blocks, enough (>= 32768) for
  // block_product_execution to split the rows over the threads.
  std::mt19937 rng(19);
  const int nodes = 2000;
  std::vector<BlockSourceFamily> families(1);
  families[0].count = 400;
  families[0].width = 10;
  std::uniform_int_distribution<int> node(0, nodes - 1);
  for (int i = 0; i < 400 * 10; ++i) families[0].global_nodes.push_back(node(rng));
  const BlockAssembly pattern(nodes, families);
  ASSERT_EQ(block_product_execution(pattern), kernels::Execution::parallel);
  const std::vector<double> blocks = random_values(9 * pattern.num_blocks(), 23u);
  const std::vector<double> x = random_values(3 * nodes, 29u), x2 = random_values(3 * nodes, 31u);
  std::vector<double> expected(3 * nodes), expected2(3 * nodes);
  kernels::block_rows_product_reference(pattern.rows(), 0, nodes, blocks.data(), x.data(), expected.data());
  kernels::block_rows_product_reference(pattern.rows(), 0, nodes, blocks.data(), x2.data(), expected2.data());
  for (int t : {1, 2}) {
    const test::ThreadCountGuard set_threads(t);
    std::vector<double> y(3 * nodes), y1(3 * nodes), y2(3 * nodes);
    block_multiply(pattern, blocks.data(), x.data(), y.data());
    block_multiply_pair(pattern, blocks.data(), x.data(), x2.data(), y1.data(), y2.data());
    EXPECT_EQ(y, expected) << t << " threads";
    EXPECT_EQ(y1, expected) << t << " threads";
    EXPECT_EQ(y2, expected2) << t << " threads";
  }
}

}  // namespace
