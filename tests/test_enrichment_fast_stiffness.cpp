// The fast enriched element stiffness (locally constant textures grouped, chunks of
// points) against the plain per-point reference: complete cuts (H exactly +-1 away from
// the cut) agree to round-off, harmonic partial cuts to the documented tolerance
// (enriched_flat_tolerance, 1e-10 relative); serial and parallel forms are bitwise equal
// for 1, 2 and 3 threads; the deformation gradients are unchanged by the chunking.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "dgtex/harmonic_enrichment.h"
#include "dgtex/heaviside.h"
#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/enriched_element_kernel.h"
#include "dgtex/kernels/enriched_quadrature.h"
#include "dgtex/mesh_generators.h"
#include "cut_element_fixture.h"
#include "shell_test_support.h"
#include "thread_count_support.h"

using namespace dgtex;

namespace {

using testing_support::max_abs;
using testing_support::max_difference;

using testing_support::CutQuad8Element;
constexpr int kT = CutQuad8Element::T;

// A rotation of up to 0.3 rad about a random axis per point.
std::vector<double> random_rotations(std::int64_t count) { return testing_support::small_random_rotations(count, 0.3, 7); }

void compare_with_reference(const CutQuad8Element& one, double tolerance) {
  const int W = one.batch.width;
  const std::vector<double> R = random_rotations(one.points());
  for (const double* rotations : {static_cast<const double*>(nullptr), R.data()}) {
    std::vector<double> K(static_cast<std::size_t>(W) * W * 9), f(3 * W), Kref(K.size()), fref(f.size());
    kernels::enriched_element_stiffness_reference(one.batch, one.quadrature(), rotations, Kref.data(), fref.data());
    kernels::enriched_element_stiffness(one.batch, one.quadrature(), rotations, K.data(), f.data(),
                                        kernels::Execution::serial);
    EXPECT_LE(max_difference(K, Kref), tolerance * max_abs(Kref)) << (rotations ? "corotated" : "linear");
    if (rotations) {
      EXPECT_GT(max_abs(fref), 0.0);
      EXPECT_LE(max_difference(f, fref), tolerance * max_abs(fref));
    }
    // Exactly symmetric.
    for (int a = 0; a < W; ++a)
      for (int c = 0; c < W; ++c)
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) ASSERT_EQ(K[(a * W + c) * 9 + i * 3 + j], K[(c * W + a) * 9 + j * 3 + i]);
    // Parallel forms bitwise equal to the serial one for any thread count.
    for (int threads : {1, 2, 3}) {
      const test::ThreadCountGuard set_threads(threads);
      std::vector<double> K2(K.size()), f2(f.size());
      kernels::enriched_element_stiffness(one.batch, one.quadrature(), rotations, K2.data(), f2.data());
      EXPECT_EQ(K2, K) << threads << " threads";
      EXPECT_EQ(f2, f) << threads << " threads";
    }
  }
}

TEST(EnrichedFastStiffness, CompleteCutsAgreeWithReferenceToRoundOff) {
  // Per-texel rule: the wall-aware adaptive rule merges the cells on both sides of straight
  // complete cuts (a few hundred points), and this comparison needs several chunks.
  const CutQuad8Element one(3, 0, /*per_texel_rule=*/true);
  ASSERT_GT(one.points(), kernels::enriched_chunk_points);  // several chunks
  compare_with_reference(one, 1e-13);
}

TEST(EnrichedFastStiffness, PartialAndCompleteCutsAgreeWithReference) {
  const CutQuad8Element one(2, 3);
  ASSERT_GT(one.points(), kernels::enriched_chunk_points);
  compare_with_reference(one, 1e-9);
}

TEST(EnrichedFastStiffness, DeformationGradientsIndependentOfThreads) {
  const CutQuad8Element one(1, 2);
  const int nodes = one.mesh.num_nodes() + static_cast<int>(one.nodes.size());
  std::vector<double> current(3 * static_cast<std::size_t>(nodes), 0.0);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  for (int n = 0; n < nodes; ++n)
    for (int c = 0; c < 3; ++c) current[3 * n + c] = (n < one.mesh.num_nodes() ? one.mesh.node(n)[c] : 0) + u(rng);
  std::vector<double> F(static_cast<std::size_t>(one.points()) * 9);
  kernels::enriched_element_deformation_gradients(one.batch, one.quadrature(), current.data(), F.data(),
                                                  kernels::Execution::serial);
  for (int threads : {1, 2, 3}) {
    const test::ThreadCountGuard set_threads(threads);
    std::vector<double> F2(F.size());
    kernels::enriched_element_deformation_gradients(one.batch, one.quadrature(), current.data(), F2.data());
    EXPECT_EQ(F2, F) << threads << " threads";
  }
  // At the rest state (enriched DOFs 0) F is the identity on the tangent plane plus t0 t0^T.
  std::vector<double> rest(current.size(), 0.0);
  std::copy(one.mesh.positions.begin(), one.mesh.positions.end(), rest.begin());
  kernels::enriched_element_deformation_gradients(one.batch, one.quadrature(), rest.data(), F.data());
  for (std::int64_t q = 0; q < one.points(); ++q)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) ASSERT_NEAR(F[9 * q + i * 3 + j], i == j ? 1.0 : 0.0, 1e-12);
}

}  // namespace
