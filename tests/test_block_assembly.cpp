// BlockAssembly against a plain reference: the pattern is every (row, col) some source
// couples, and each global block (and node vector) is the sum of its contributions in
// (family, source, local a, local b) order, so the results are bitwise the reference's
// sums for any thread count; the symmetric walk equals the general one on upper blocks
// and mirrors them exactly.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <utility>
#include <vector>

#include "dgtex/block_assembly.h"
#include "thread_count_support.h"

namespace dgtex {
namespace {

struct RandomFamilies {
  int num_nodes = 0;
  std::vector<BlockSourceFamily> families;
  std::vector<std::vector<double>> matrices, vectors;  // per family: count x width^2 x 9, count x width x 3
};

// Sources with random widths, unused slots (-1) and shared nodes; symmetric local
// matrices (assemble_symmetric_matrix needs them), values spread over many magnitudes so
// that a different summation order changes the bits.
RandomFamilies random_families(unsigned seed) {
  std::mt19937 rng(seed);
  RandomFamilies r;
  r.num_nodes = 40;
  std::uniform_int_distribution<int> node(0, r.num_nodes - 1), coin(0, 5);
  std::uniform_real_distribution<double> mantissa(-1.0, 1.0);
  std::uniform_int_distribution<int> exponent(-20, 20);
  auto value = [&] { return std::ldexp(mantissa(rng), exponent(rng)); };
  for (int width : {3, 8, 13}) {
    BlockSourceFamily f;
    f.count = 7 + width;
    f.width = width;
    for (int s = 0; s < f.count; ++s) {
      std::vector<int> nodes;
      while (static_cast<int>(nodes.size()) < width) {
        const int n = coin(rng) == 0 ? -1 : node(rng);
        bool repeated = false;
        for (int m : nodes) repeated = repeated || (n >= 0 && m == n);
        if (!repeated) nodes.push_back(n);
      }
      f.global_nodes.insert(f.global_nodes.end(), nodes.begin(), nodes.end());
    }
    std::vector<double> m(static_cast<size_t>(f.count) * width * width * 9);
    for (int s = 0; s < f.count; ++s)
      for (int a = 0; a < width; ++a)
        for (int b = a; b < width; ++b)
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) {
              if (a == b && j < i) continue;
              const double v = value();
              m[((static_cast<size_t>(s) * width + a) * width + b) * 9 + i * 3 + j] = v;
              m[((static_cast<size_t>(s) * width + b) * width + a) * 9 + j * 3 + i] = v;
            }
    std::vector<double> vec(static_cast<size_t>(f.count) * width * 3);
    for (double& v : vec) v = value();
    r.families.push_back(std::move(f));
    r.matrices.push_back(std::move(m));
    r.vectors.push_back(std::move(vec));
  }
  return r;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(BlockAssembly, PatternAndSumsAreTheReferenceOnesBitwiseForAnyThreadCount) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const RandomFamilies r = random_families(seed);
    // Reference: contributions visited family by family, source by source, a then b.
    std::map<std::pair<int, int>, std::vector<double>> blocks;
    std::vector<double> node_vector(static_cast<size_t>(r.num_nodes) * 3, 0.0);
    for (size_t f = 0; f < r.families.size(); ++f) {
      const BlockSourceFamily& fam = r.families[f];
      for (int s = 0; s < fam.count; ++s)
        for (int a = 0; a < fam.width; ++a) {
          const int row = fam.global_nodes[static_cast<size_t>(s) * fam.width + a];
          if (row < 0) continue;
          for (int c = 0; c < 3; ++c)
            node_vector[3 * row + c] += r.vectors[f][(static_cast<size_t>(s) * fam.width + a) * 3 + c];
          for (int b = 0; b < fam.width; ++b) {
            const int col = fam.global_nodes[static_cast<size_t>(s) * fam.width + b];
            if (col < 0) continue;
            std::vector<double>& sum = blocks[{row, col}];
            sum.resize(9, 0.0);
            for (int k = 0; k < 9; ++k)
              sum[k] += r.matrices[f][((static_cast<size_t>(s) * fam.width + a) * fam.width + b) * 9 + k];
          }
        }
    }
    const BlockAssembly pattern(r.num_nodes, r.families);
    ASSERT_EQ(pattern.num_blocks(), static_cast<std::int64_t>(blocks.size()));
    std::int64_t k = 0;
    for (const auto& [key, sum] : blocks) {
      ASSERT_GE(pattern.row_start()[key.first + 1], k + 1) << "block (" << key.first << ", " << key.second << ")";
      ASSERT_EQ(pattern.column()[k], key.second) << "row " << key.first;
      ASSERT_EQ(pattern.find(key.first, key.second), k);
      ++k;
    }
    std::vector<const double*> matrices, vectors;
    std::vector<LocalMatrices> symmetric;
    for (size_t f = 0; f < r.families.size(); ++f) {
      matrices.push_back(r.matrices[f].data());
      vectors.push_back(r.vectors[f].data());
      symmetric.push_back({r.matrices[f].data(), 0});
    }
    for (int threads : {1, 2, 3}) {
      const test::ThreadCountGuard set_threads(threads);
      std::vector<double> general(pattern.num_blocks() * 9), mirrored(general.size()), out(node_vector.size());
      pattern.assemble_matrix(matrices, general.data());
      pattern.assemble_symmetric_matrix(symmetric, mirrored.data());
      pattern.assemble_vector(vectors, out.data());
      k = 0;
      for (const auto& [key, sum] : blocks) {
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            ASSERT_TRUE(same_bits(general[k * 9 + i * 3 + j], sum[i * 3 + j]))
                << "seed " << seed << ", " << threads << " threads, block (" << key.first << ", " << key.second << ")";
            // Upper blocks (and the diagonal's upper triangle) are the same sums; the rest
            // are their mirrors.
            const bool upper = key.second > key.first || (key.second == key.first && j >= i);
            const double expected =
                upper ? sum[i * 3 + j] : general[pattern.find(key.second, key.first) * 9 + j * 3 + i];
            ASSERT_TRUE(same_bits(mirrored[k * 9 + i * 3 + j], expected))
                << "seed " << seed << ", " << threads << " threads, symmetric block (" << key.first << ", "
                << key.second << ")";
          }
        ++k;
      }
      for (size_t i = 0; i < out.size(); ++i) ASSERT_TRUE(same_bits(out[i], node_vector[i])) << "node vector entry " << i;
    }
  }
}

// The products fused into assemble_matrix are those of the kernels on the assembled
// matrix, bit for bit, for one vector and for two, on any thread count; the sums are
// unchanged by them.
TEST(BlockAssembly, FusedProductsAreTheKernelsProductsOfTheSumBitwise) {
  const RandomFamilies r = random_families(4);
  const BlockAssembly pattern(r.num_nodes, r.families);
  std::vector<const double*> matrices;
  for (const std::vector<double>& m : r.matrices) matrices.push_back(m.data());
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const std::size_t n = 3 * static_cast<std::size_t>(r.num_nodes);
  std::vector<double> x1(n), x2(n);
  for (double& v : x1) v = uniform(rng);
  for (double& v : x2) v = std::ldexp(uniform(rng), 30);
  std::vector<double> spread1(3 * n), spread2(3 * n);
  kernels::spread_block_vector(r.num_nodes, x1.data(), spread1.data());
  kernels::spread_block_vector(r.num_nodes, x2.data(), spread2.data());

  std::vector<double> sums(pattern.num_blocks() * 9), expected1(n), expected2(n);
  pattern.assemble_matrix(matrices, sums.data(), false);
  kernels::block_rows_product(pattern.rows(), 0, r.num_nodes, sums.data(), spread1.data(), expected1.data());
  kernels::block_rows_product(pattern.rows(), 0, r.num_nodes, sums.data(), spread2.data(), expected2.data());
  for (int threads : {1, 2, 3}) {
    const test::ThreadCountGuard set_threads(threads);
    for (bool pair : {false, true}) {
      std::vector<double> fused_sums(sums.size()), y1(n, 7.0), y2(n, 7.0);
      const AssembledProducts products{spread1.data(), pair ? spread2.data() : nullptr, y1.data(),
                                       pair ? y2.data() : nullptr};
      pattern.assemble_matrix(matrices, fused_sums.data(), true, &products);
      for (std::size_t i = 0; i < sums.size(); ++i)
        ASSERT_TRUE(same_bits(fused_sums[i], sums[i])) << threads << " threads, sum entry " << i;
      for (std::size_t i = 0; i < n; ++i) {
        ASSERT_TRUE(same_bits(y1[i], expected1[i])) << threads << " threads, pair " << pair << ", A x1 entry " << i;
        ASSERT_TRUE(same_bits(y2[i], pair ? expected2[i] : 7.0)) << threads << " threads, pair " << pair
                                                                 << ", A x2 entry " << i;
      }
    }
  }
}

// Sources of different widths (BlockSourceFamily::widths): each family of the random ones
// with its unused slots dropped, so every source keeps only its used functions, back to back.
// The same contributions in the same order: the same pattern and bitwise the same sums as
// the padded families, for any thread count; the symmetric walk refuses such a family.
TEST(BlockAssembly, SourcesOfDifferentWidthsSumAsTheirPaddedFamilyBitwise) {
  const RandomFamilies padded = random_families(4);
  RandomFamilies compact;
  compact.num_nodes = padded.num_nodes;
  for (size_t f = 0; f < padded.families.size(); ++f) {
    const BlockSourceFamily& fam = padded.families[f];
    BlockSourceFamily c;
    c.count = fam.count;
    std::vector<double> m, vec;
    for (int s = 0; s < fam.count; ++s) {
      const int* g = fam.global_nodes.data() + static_cast<size_t>(s) * fam.width;
      std::vector<int> used;
      for (int a = 0; a < fam.width; ++a)
        if (g[a] >= 0) used.push_back(a);
      c.widths.push_back(static_cast<int>(used.size()));
      for (int a : used) {
        c.global_nodes.push_back(g[a]);
        for (int k = 0; k < 3; ++k) vec.push_back(padded.vectors[f][(static_cast<size_t>(s) * fam.width + a) * 3 + k]);
        for (int b : used)
          for (int k = 0; k < 9; ++k)
            m.push_back(padded.matrices[f][((static_cast<size_t>(s) * fam.width + a) * fam.width + b) * 9 + k]);
      }
    }
    ASSERT_LT(c.global_nodes.size(), fam.global_nodes.size()) << "family " << f << " has no unused slot";
    compact.families.push_back(std::move(c));
    compact.matrices.push_back(std::move(m));
    compact.vectors.push_back(std::move(vec));
  }
  const BlockAssembly reference(padded.num_nodes, padded.families), pattern(compact.num_nodes, compact.families);
  ASSERT_EQ(pattern.row_start(), reference.row_start());
  ASSERT_EQ(pattern.column(), reference.column());
  std::vector<const double*> padded_matrices, compact_matrices, padded_vectors, compact_vectors;
  for (size_t f = 0; f < padded.families.size(); ++f) {
    padded_matrices.push_back(padded.matrices[f].data());
    compact_matrices.push_back(compact.matrices[f].data());
    padded_vectors.push_back(padded.vectors[f].data());
    compact_vectors.push_back(compact.vectors[f].data());
  }
  std::vector<double> expected_matrix(reference.num_blocks() * 9), expected_vector(3 * static_cast<size_t>(padded.num_nodes));
  reference.assemble_matrix(padded_matrices, expected_matrix.data(), false);
  reference.assemble_vector(padded_vectors, expected_vector.data(), false);
  for (int threads : {1, 2, 3}) {
    const test::ThreadCountGuard set_threads(threads);
    std::vector<double> matrix(expected_matrix.size(), -1.0), vector(expected_vector.size(), -1.0);
    pattern.assemble_matrix(compact_matrices, matrix.data());
    pattern.assemble_vector(compact_vectors, vector.data());
    for (size_t i = 0; i < matrix.size(); ++i) ASSERT_TRUE(same_bits(matrix[i], expected_matrix[i])) << "entry " << i;
    for (size_t i = 0; i < vector.size(); ++i) ASSERT_TRUE(same_bits(vector[i], expected_vector[i])) << "entry " << i;
  }
  std::vector<LocalMatrices> locals;
  for (const double* m : compact_matrices) locals.push_back({m, 0});
  std::vector<double> symmetric(expected_matrix.size());
  EXPECT_THROW(pattern.assemble_symmetric_matrix(locals, symmetric.data()), std::logic_error);
  // Widths and nodes that do not match are refused.
  std::vector<BlockSourceFamily> short_nodes = compact.families;
  short_nodes[0].global_nodes.pop_back();
  EXPECT_THROW(BlockAssembly(compact.num_nodes, short_nodes), std::invalid_argument);
  std::vector<BlockSourceFamily> few_widths = compact.families;
  few_widths[0].widths.pop_back();
  EXPECT_THROW(BlockAssembly(compact.num_nodes, few_widths), std::invalid_argument);
}

}  // namespace
}  // namespace dgtex
