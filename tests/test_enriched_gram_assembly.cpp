// The blocked enriched element stiffness: the Gram accumulation and the products A^T B
// (dgtex/kernels/gram_accumulation.h) are bitwise the one-entry-at-a-time references (every
// multiply-add fused) on every instruction-set path the machine supports, and the fast
// stiffness (frame-split sums of the strain rows, blocked products, runs-based group
// mapping, row-parallel chunk reduction) agrees with the plain per-point reference to
// round-off for complete cuts (1e-13 relative to max |K|) and to the flat tolerance for
// harmonic partial cuts (1e-9), on flat and curved elements, writes exact zeros into
// padding slots, is exactly symmetric, and is bitwise the same for 1, 2 and 4 threads;
// GramAccumulator (the mass and edge sums) matches the plain sum to round-off, and so do
// the weighted Gram sums of the bending rows (bitwise their reference on every path); the
// scaled row gather is bitwise its fused sum on every path. The fused corotated form (F and
// rotation per point inside the stiffness pass) is bitwise the three kernels.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "dgtex/kernels/gram_accumulation.h"
#include "dgtex/harmonic_enrichment.h"
#include "dgtex/heaviside.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/enriched_element_kernel.h"
#include "dgtex/kernels/enriched_quadrature.h"
#include "dgtex/kernels/polar_decomposition.h"
#include "dgtex/mesh_generators.h"
#include "cut_element_fixture.h"
#include "shell_test_support.h"
#include "vector_path_support.h"
#include "thread_count_support.h"

using namespace dgtex;

namespace {

TEST(EnrichedGram, EveryPathIsBitwiseTheReference) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int cols : {16, 48, 128}) {
    for (int rows : {6, 96}) {
      std::vector<double> A(static_cast<std::size_t>(rows) * cols);
      for (double& x : A) x = u(rng);
      for (int c = 0; c < cols; ++c)
        if (c % 7 == 3) A[c] = 0;  // a few zeros and exact cancellations
      std::vector<double> start(static_cast<std::size_t>(cols) * cols);
      for (double& x : start) x = u(rng);
      for (bool overwrite : {true, false}) {
        std::vector<double> expected = start;
        kernels::accumulate_gram_upper_reference(rows, cols, A.data(), expected.data(), overwrite);
        for (kernels::VectorPath path : testing_support::supported_vector_paths()) {
          std::vector<double> G = start;
          kernels::accumulate_gram_upper(rows, cols, A.data(), G.data(), overwrite, path);
          for (int i = 0; i < cols; ++i)
            for (int j = i; j < cols; ++j)
              ASSERT_EQ(G[static_cast<std::size_t>(i) * cols + j], expected[static_cast<std::size_t>(i) * cols + j])
                  << "path " << static_cast<int>(path) << " cols " << cols << " rows " << rows << " (" << i << ", "
                  << j << ")";
        }
      }
    }
  }
}

TEST(EnrichedGram, ProductOnEveryPathIsBitwiseTheReference) {
  // A^T B, whole or upper, with column counts that end in a tile narrower than the widest
  // (8 past a multiple of 16) and row counts of one and of several stacked points.
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int cols : {8, 24, 72, 80}) {
    for (int rows : {2, 48}) {
      std::vector<double> A(static_cast<std::size_t>(rows) * cols), B(A.size());
      for (double& x : A) x = u(rng);
      for (double& x : B) x = u(rng);
      for (int c = 0; c < cols; c += 5) A[c] = 0, B[c + 1 < cols ? c + 1 : c] = -A[c];
      std::vector<double> start(static_cast<std::size_t>(cols) * cols);
      for (double& x : start) x = u(rng);
      for (bool upper : {true, false})
        for (bool overwrite : {true, false}) {
          std::vector<double> expected = start;
          kernels::accumulate_product_reference(rows, cols, A.data(), B.data(), expected.data(), overwrite, upper);
          for (kernels::VectorPath path : testing_support::supported_vector_paths()) {
            std::vector<double> G = start;
            kernels::accumulate_product(rows, cols, A.data(), B.data(), G.data(), overwrite, upper, path);
            for (int i = 0; i < cols; ++i)
              for (int j = upper ? i : 0; j < cols; ++j)
                ASSERT_EQ(G[static_cast<std::size_t>(i) * cols + j], expected[static_cast<std::size_t>(i) * cols + j])
                    << "path " << static_cast<int>(path) << " cols " << cols << " rows " << rows << " upper " << upper
                    << " (" << i << ", " << j << ")";
          }
        }
    }
  }
}

TEST(EnrichedGram, WeightedGramsOnEveryPathAreBitwiseTheReference) {
  // Six weighted sums of 3-row points (the frame split's bending sums), stored or added per
  // sum, with column counts that end in a tile narrower than the widest; the reference is
  // itself within round-off of six products of the weighted rows (sqrt(w) a_r, w >= 0).
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> u(-1, 1), positive(0, 1);
  constexpr int sums = 6, rows_per_point = 3;
  for (int cols : {8, 24, 40}) {
    for (int points : {1, 16}) {
      std::vector<double> A(static_cast<std::size_t>(points) * rows_per_point * cols), weights(points * sums);
      for (double& x : A) x = u(rng);
      for (int c = 0; c < cols; c += 6) A[c] = 0;
      for (double& w : weights) w = positive(rng);
      std::vector<std::vector<double>> start(sums, std::vector<double>(static_cast<std::size_t>(cols) * cols));
      for (auto& G : start)
        for (double& x : G) x = u(rng);
      const bool overwrite[sums] = {false, true, false, true, true, false};
      std::vector<std::vector<double>> expected = start;
      double* expected_at[sums];
      for (int k = 0; k < sums; ++k) expected_at[k] = expected[k].data();
      kernels::accumulate_weighted_grams_reference(points, rows_per_point, cols, A.data(), weights.data(), sums,
                                                   expected_at, overwrite);
      for (int k = 0; k < sums; ++k) {  // the same sums as products of weighted rows
        std::vector<double> weighted(A.size()), plain = start[k];
        for (int p = 0; p < points; ++p)
          for (std::size_t x = 0; x < static_cast<std::size_t>(rows_per_point) * cols; ++x)
            weighted[p * rows_per_point * cols + x] =
                std::sqrt(weights[p * sums + k]) * A[p * rows_per_point * cols + x];
        kernels::accumulate_product_reference(points * rows_per_point, cols, weighted.data(), weighted.data(),
                                              plain.data(), overwrite[k], true);
        for (int i = 0; i < cols; ++i)
          for (int j = i; j < cols; ++j)
            ASSERT_NEAR(expected[k][static_cast<std::size_t>(i) * cols + j],
                        plain[static_cast<std::size_t>(i) * cols + j], 1e-13 * (1 + points))
                << "sum " << k << " (" << i << ", " << j << ")";
      }
      for (kernels::VectorPath path : testing_support::supported_vector_paths()) {
        std::vector<std::vector<double>> G = start;
        double* at[sums];
        for (int k = 0; k < sums; ++k) at[k] = G[k].data();
        kernels::accumulate_weighted_grams(points, rows_per_point, cols, A.data(), weights.data(), sums, at, overwrite,
                                           path);
        for (int k = 0; k < sums; ++k)
          for (int i = 0; i < cols; ++i)
            for (int j = i; j < cols; ++j)
              ASSERT_EQ(G[k][static_cast<std::size_t>(i) * cols + j],
                        expected[k][static_cast<std::size_t>(i) * cols + j])
                  << "path " << static_cast<int>(path) << " cols " << cols << " points " << points << " sum " << k
                  << " (" << i << ", " << j << ")";
      }
    }
  }
  double* none[1] = {nullptr};
  const bool no[1] = {false};
  EXPECT_THROW(kernels::accumulate_weighted_grams(1, 3, 8, nullptr, nullptr, 7, none, no), std::invalid_argument);
}

TEST(EnrichedGram, ScaledRowOnEveryPathIsBitwiseTheFusedSum) {
  // out[j] + (s scales[j]) g[j] with the add fused, for counts that end in a tail shorter
  // than every vector width.
  std::mt19937 rng(14);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int count : {1, 3, 7, 16, 29, 69}) {
    std::vector<double> scales(count), g(count), start(count);
    for (double& x : scales) x = u(rng);
    for (double& x : g) x = u(rng);
    for (double& x : start) x = u(rng);
    const double s = u(rng);
    std::vector<double> expected = start;
    for (int j = 0; j < count; ++j) expected[j] = std::fma(s * scales[j], g[j], start[j]);
    for (kernels::VectorPath path : testing_support::supported_vector_paths()) {
      std::vector<double> out = start;
      kernels::add_scaled_row(count, s, scales.data(), g.data(), out.data(), path);
      for (int j = 0; j < count; ++j)
        ASSERT_EQ(out[j], expected[j]) << "path " << static_cast<int>(path) << " count " << count << " entry " << j;
    }
  }
}

TEST(EnrichedGram, AccumulatorMatchesThePlainSum) {
  // 250 rows of 37 entries (several blocks, padded columns): within 1e-14 of max |A| of
  // the plain double sum, exactly symmetric, and a capacity hint below the row count
  // changes nothing.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  const int n = 37, rows = 250;
  std::vector<double> V(static_cast<std::size_t>(rows) * n);
  for (double& x : V) x = u(rng);
  kernels::GramAccumulator A(n), B(n, 40), empty(n);
  for (int r = 0; r < rows; ++r) {
    std::copy(V.begin() + r * n, V.begin() + (r + 1) * n, A.next());
    A.push();
    std::copy(V.begin() + r * n, V.begin() + (r + 1) * n, B.next());
    B.push();
  }
  A.flush(), B.flush(), empty.flush();
  double largest = 0;
  for (int i = 0; i < n; ++i) largest = std::max(largest, std::abs(A(i, i)));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      double plain = 0;
      for (int r = 0; r < rows; ++r) plain += V[r * n + i] * V[r * n + j];
      ASSERT_NEAR(A(i, j), plain, 1e-14 * largest);
      ASSERT_EQ(A(i, j), A(j, i));
      ASSERT_EQ(empty(i, j), 0.0);
    }
  // B's blocks of 40 rows sum differently from A's 96, but agree to round-off.
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) ASSERT_NEAR(B(i, j), A(i, j), 1e-14 * largest);
}

// One quad8 element with complete and partial cuts, its local basis padded by unused slots.
struct PaddedElement : testing_support::CutQuad8Element {
  PaddedElement(int complete, int partial, int extra) : CutQuad8Element(complete, partial, false, extra) {}
};

std::vector<double> small_rotations(std::int64_t count) { return testing_support::small_random_rotations(count, 0.4, 5); }

void check_against_reference(const PaddedElement& one, double tolerance) {
  const int W = one.batch.width;
  const std::vector<double> R = small_rotations(one.qp_start.back());
  for (const double* rotations : {static_cast<const double*>(nullptr), R.data()}) {
    std::vector<double> Kref(static_cast<std::size_t>(W) * W * 9), fref(3 * W);
    kernels::enriched_element_stiffness_reference(one.batch, one.quadrature(), rotations, Kref.data(), fref.data());
    std::vector<double> K(Kref.size(), std::nan("")), f(fref.size(), std::nan(""));
    kernels::enriched_element_stiffness(one.batch, one.quadrature(), rotations, K.data(), f.data(),
                                        kernels::Execution::serial);
    double kmax = 0, fmax = 0, kdiff = 0, fdiff = 0;
    for (std::size_t i = 0; i < K.size(); ++i)
      kmax = std::max(kmax, std::abs(Kref[i])), kdiff = std::max(kdiff, std::abs(K[i] - Kref[i]));
    for (std::size_t i = 0; i < f.size(); ++i)
      fmax = std::max(fmax, std::abs(fref[i])), fdiff = std::max(fdiff, std::abs(f[i] - fref[i]));
    EXPECT_LE(kdiff, tolerance * kmax) << (rotations ? "corotated" : "linear");
    if (rotations) {
      ASSERT_GT(fmax, 0.0);
      EXPECT_LE(fdiff, tolerance * fmax);
    }
    for (int a = 0; a < W; ++a)
      for (int c = 0; c < W; ++c)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            const double v = K[(a * W + c) * 9 + i * 3 + j];
            if (a >= one.n || c >= one.n) {
              ASSERT_EQ(v, 0.0) << "padding block (" << a << ", " << c << ")";
            }
            ASSERT_EQ(v, K[(c * W + a) * 9 + j * 3 + i]);  // exactly symmetric
          }
    for (int i = 3 * one.n; i < 3 * W; ++i) ASSERT_EQ(f[i], 0.0);
    for (int threads : {1, 2, 4}) {
      const test::ThreadCountGuard set_threads(threads);
      std::vector<double> K2(K.size(), std::nan("")), f2(f.size(), std::nan(""));
      kernels::enriched_element_stiffness(one.batch, one.quadrature(), rotations, K2.data(), f2.data());
      EXPECT_EQ(K2, K) << threads << " threads";
      EXPECT_EQ(f2, f) << threads << " threads";
    }
  }
}

TEST(EnrichedBlockedStiffness, CompleteCutsMatchTheReferenceToRoundOff) {
  const PaddedElement one(2, 0, 3);
  check_against_reference(one, 1e-13);
}

TEST(EnrichedBlockedStiffness, PartialCutsMatchTheReferenceAndThreadsAgreeBitwise) {
  const PaddedElement one(1, 3, 2);
  ASSERT_GT(one.qp_start.back(), kernels::enriched_chunk_points);  // several chunks, reduced per block row
  check_against_reference(one, 1e-9);
}

TEST(EnrichedBlockedStiffness, CurvedElementMatchesTheReferenceLinearAndRotated) {
  // Every midside node lifted out of the plane: each point has its own rest frame, and
  // with random rotations its own rotated frame, in every component block of the
  // frame-split sums.
  PaddedElement one(1, 2, 1);
  for (int a = 4; a < 8; ++a) one.mesh.positions[3 * one.mesh.element_nodes(0)[a] + 2] += 0.05 * (a % 2 ? 1 : -1);
  double frame[9];
  ASSERT_FALSE(kernels::enriched_element_planar_frame(one.batch, 0, frame));
  check_against_reference(one, 1e-9);
}

TEST(EnrichedBlockedStiffness, FusedCorotationIsBitwiseTheSeparateKernels) {
  const PaddedElement one(1, 2, 1);
  const int W = one.batch.width;
  const int nodes = one.mesh.num_nodes() + static_cast<int>(one.nodes.size());
  std::vector<double> current(3 * static_cast<std::size_t>(nodes), 0.0);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-0.03, 0.03);
  for (int v = 0; v < nodes; ++v)
    for (int c = 0; c < 3; ++c) current[3 * v + c] = (v < one.mesh.num_nodes() ? one.mesh.node(v)[c] : 0) + u(rng);
  const std::int64_t points = one.qp_start.back();
  std::vector<double> F(static_cast<std::size_t>(points) * 9), R(F.size());
  kernels::enriched_element_deformation_gradients(one.batch, one.quadrature(), current.data(), F.data());
  kernels::polar_decomposition_batch(points, F.data(), R.data());
  std::vector<double> K(static_cast<std::size_t>(W) * W * 9), f(3 * W);
  kernels::enriched_element_stiffness(one.batch, one.quadrature(), R.data(), K.data(), f.data());
  double fmax = 0;
  for (double x : f) fmax = std::max(fmax, std::abs(x));
  ASSERT_GT(fmax, 0.0);
  for (int threads : {1, 2, 4}) {
    const test::ThreadCountGuard set_threads(threads);
    std::vector<double> K2(K.size(), std::nan("")), f2(f.size(), std::nan(""));
    kernels::enriched_element_corotated_stiffness(one.batch, one.quadrature(), current.data(), K2.data(), f2.data());
    EXPECT_EQ(K2, K) << threads << " threads";
    EXPECT_EQ(f2, f) << threads << " threads";
  }
}

}  // namespace
