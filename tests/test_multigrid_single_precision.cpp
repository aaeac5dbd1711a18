// The single-precision preconditioner cycle (LaplaceMultigridOptions::single_precision_min_texels):
// float kernels against their serial references (bitwise, 1 and 2 threads), the float
// setup against the double kernels rounded, and whole solves (float vs double cycle, thread
// counts, tight tolerances).
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <random>
#include <vector>

#include "dgtex/kernels/multigrid_galerkin.h"
#include "dgtex/kernels/multigrid_residual.h"
#include "dgtex/kernels/multigrid_smooth.h"
#include "dgtex/kernels/multigrid_transfer.h"
#include "dgtex/kernels/multigrid_unknowns.h"
#include "dgtex/laplace_direct.h"
#include "dgtex/laplace_domains.h"
#include "dgtex/laplace_multigrid.h"
#include "multigrid_buffer.h"
#include "thread_count_support.h"

namespace dgtex {
namespace {
using namespace kernels;

// Level 0, a float level 1 and a float level 2 of a domain (float setup kernels), with random
// vectors (fixed seed) on every level.
struct FloatLevels {
  GridShape fine, coarse, coarser;
  std::vector<std::uint8_t> bits;
  std::vector<std::vector<float>> p1, a1, p2, a2;  // interpolation to / operator on levels 1 and 2
  std::vector<double> x, b;                        // level 0
  std::vector<float> x1, b1, x2;
  static InterpolationArraysFloat P(std::vector<std::vector<float>>& p) {
    return {p[0].data(), p[1].data(), p[2].data(), p[3].data(), p[4].data(), p[5].data(), p[6].data(), p[7].data()};
  }
  static Stencil9ArraysFloat A(std::vector<std::vector<float>>& a) {
    return {a[0].data(), a[1].data(), a[2].data(), a[3].data(), a[4].data()};
  }

  explicit FloatLevels(const TexelTile& tile) {
    std::vector<std::uint8_t> tile_bits;
    classify_laplace_texels(tile, tile_bits);
    fine = {tile.width, tile.height};
    coarse = fine.coarser();
    coarser = coarse.coarser();
    bits.assign(fine.padded_size(), 0);
    for (int j = 0; j < fine.ny; ++j)
      for (int i = 0; i < fine.nx; ++i) bits[fine.at(i, j)] = tile_bits[tile.index(i, j)];
    p1.assign(8, std::vector<float>(coarse.padded_size(), 0.0f));
    a1.assign(5, std::vector<float>(coarse.padded_size(), 0.0f));
    p2.assign(8, std::vector<float>(coarser.padded_size(), 0.0f));
    a2.assign(5, std::vector<float>(coarser.padded_size(), 0.0f));
    build_interpolation_texels(fine, bits.data(), P(p1), Execution::serial);
    galerkin_texels(fine, bits.data(), P(p1).view(), A(a1), Execution::serial);
    build_interpolation_stencil9(coarse, A(a1).view(), P(p2), Execution::serial);
    galerkin_stencil9(coarse, A(a1).view(), P(p2).view(), A(a2), Execution::serial);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1, 1);
    auto random_interior = [&](GridShape g, auto zero) {
      std::vector<decltype(zero)> v(g.padded_size(), zero);
      for (int j = 0; j < g.ny; ++j)
        for (int i = 0; i < g.nx; ++i) v[g.at(i, j)] = static_cast<decltype(zero)>(u(rng));
      return v;
    };
    x = random_interior(fine, 0.0);
    b = random_interior(fine, 0.0);
    x1 = random_interior(coarse, 0.0f);
    b1 = random_interior(coarse, 0.0f);
    x2 = random_interior(coarser, 0.0f);
  }
};

// Runs `parallel` with 1 and 2 OpenMP threads; both results must equal `reference`.
template <class Vector, class Parallel>
void expect_equal_for_thread_counts(const Vector& reference, Parallel parallel, const char* what) {
  for (int threads : {1, 2}) {
    const test::ThreadCountGuard set_threads(threads);
    EXPECT_EQ(parallel(), reference) << what << ", " << threads << " threads";
  }
}

// Run first (before the parameterised suite fills the block cache): a dirty cached block.
TEST(MultigridFrameZeroedFloatBuffer, GhostFrameIsZeroAndPoisonReachesTheInterior) {
  const std::size_t nx = 194, ny = 130;  // 100 KB of floats: a cached block
  { detail::FloatMultigridBuffer garbage(nx * ny, -3.0f); }
  detail::set_poison_unzeroed_blocks(true);
  const detail::FloatMultigridBuffer v = detail::frame_zeroed_float_buffer(nx, ny);
  detail::set_poison_unzeroed_blocks(false);
  int nan_interior = 0;
  for (std::size_t j = 0; j < ny; ++j)
    for (std::size_t i = 0; i < nx; ++i) {
      const bool ghost = i == 0 || j == 0 || i + 1 == nx || j + 1 == ny;
      if (ghost) EXPECT_EQ(v[j * nx + i], 0.0f) << i << ", " << j;
      else nan_interior += std::isnan(v[j * nx + i]) ? 1 : 0;
    }
  EXPECT_EQ(nan_interior, static_cast<int>((nx - 2) * (ny - 2)));
}

class MultigridSinglePrecision : public ::testing::TestWithParam<LaplaceDomain> {};

TEST_P(MultigridSinglePrecision, FloatKernelsEqualReferencesBitwise) {
  FloatLevels L(make_laplace_domain(GetParam(), 97));
  const Stencil9ViewFloat a1 = FloatLevels::A(L.a1).view();
  const InterpolationViewFloat p1 = FloatLevels::P(L.p1).view(), p2 = FloatLevels::P(L.p2).view();
  for (bool forward : {true, false}) {
    std::vector<float> ref = L.x1;
    for (int k = 0; k < 4; ++k) smooth_stencil9_color_reference(L.coarse, a1, L.b1.data(), ref.data(), forward ? k : 3 - k);
    expect_equal_for_thread_counts(ref, [&] {
      std::vector<float> x = L.x1;
      smooth_stencil9_sweep(L.coarse, a1, L.b1.data(), x.data(), forward, Execution::parallel);
      return x;
    }, "smooth_stencil9_sweep");
  }
  {
    std::vector<float> r(L.x1.size(), 0.0f);
    std::vector<double> rows(L.coarse.ny, 0.0);
    residual_stencil9_reference(L.coarse, a1, L.b1.data(), L.x1.data(), r.data(), rows.data());
    expect_equal_for_thread_counts(r, [&] {
      std::vector<float> out(L.x1.size(), 0.0f);
      std::vector<double> out_rows(L.coarse.ny, 0.0);
      residual_stencil9(L.coarse, a1, L.b1.data(), L.x1.data(), out.data(), out_rows.data(), Execution::parallel);
      EXPECT_EQ(out_rows, rows);
      return out;
    }, "residual_stencil9");
  }
  {
    std::vector<float> ref(L.coarser.padded_size(), 0.0f);
    restrict_residual_reference(L.coarse, L.coarser, p2, L.x1.data(), ref.data());
    expect_equal_for_thread_counts(ref, [&] {
      std::vector<float> out(L.coarser.padded_size(), 0.0f);
      restrict_residual(L.coarse, L.coarser, p2, L.x1.data(), out.data(), Execution::parallel);
      return out;
    }, "restrict_residual");
  }
  {
    std::vector<std::uint8_t> active(L.coarse.padded_size(), 0);
    for (int j = 0; j < L.coarse.ny; ++j)
      for (int i = 0; i < L.coarse.nx; ++i) active[L.coarse.at(i, j)] = L.a1[0][L.coarse.at(i, j)] > 0;
    std::vector<float> ref = L.x1;
    prolong_correction_reference(L.coarse, L.coarser, p2, L.x2.data(), active.data(), ref.data());
    expect_equal_for_thread_counts(ref, [&] {
      std::vector<float> out = L.x1;
      prolong_correction(L.coarse, L.coarser, p2, L.x2.data(), active.data(), out.data(), Execution::parallel);
      return out;
    }, "prolong_correction");
  }
  // Level 0 (double) <-> level 1 (float).
  {
    std::vector<float> ref(L.coarse.padded_size(), 0.0f);
    restrict_red_residual_reference(L.fine, L.coarse, p1, L.x.data(), ref.data());
    expect_equal_for_thread_counts(ref, [&] {
      std::vector<float> out(L.coarse.padded_size(), 0.0f);
      restrict_red_residual(L.fine, L.coarse, p1, L.x.data(), out.data(), Execution::parallel);
      return out;
    }, "restrict_red_residual");
    // The double form, rounded once, gives the same floats (sums are formed in double).
    std::vector<std::vector<double>> p1d(8);
    for (int k = 0; k < 8; ++k) p1d[k].assign(L.p1[k].begin(), L.p1[k].end());
    const InterpolationView p1_double{p1d[0].data(), p1d[1].data(), p1d[2].data(), p1d[3].data(),
                                      p1d[4].data(), p1d[5].data(), p1d[6].data(), p1d[7].data()};
    std::vector<double> wide(L.coarse.padded_size(), 0.0);
    restrict_red_residual_reference(L.fine, L.coarse, p1_double, L.x.data(), wide.data());
    EXPECT_EQ(std::vector<float>(wide.begin(), wide.end()), ref);
  }
  {
    std::vector<float> ref(L.coarse.padded_size(), 0.0f);
    restrict_red_residual_texels_reference(L.fine, L.coarse, p1, L.bits.data(), L.b.data(), L.x.data(), ref.data());
    expect_equal_for_thread_counts(ref, [&] {
      std::vector<float> out(L.coarse.padded_size(), 0.0f);
      restrict_red_residual_texels(L.fine, L.coarse, p1, L.bits.data(), L.b.data(), L.x.data(), out.data(),
                                   Execution::parallel);
      return out;
    }, "restrict_red_residual_texels");
  }
  {
    std::vector<std::uint8_t> active(L.fine.padded_size(), 0);
    for (std::size_t t = 0; t < active.size(); ++t) active[t] = (L.bits[t] & is_unknown) ? 1 : 0;
    std::vector<double> ref = L.x;
    prolong_correction_red_reference(L.fine, L.coarse, p1, L.x1.data(), active.data(), ref.data());
    expect_equal_for_thread_counts(ref, [&] {
      std::vector<double> out = L.x;
      prolong_correction_red(L.fine, L.coarse, p1, L.x1.data(), active.data(), out.data(), Execution::parallel);
      return out;
    }, "prolong_correction_red");
  }
}

TEST_P(MultigridSinglePrecision, FloatSetupIsTheDoubleSetupRoundedAndThreadIndependent) {
  FloatLevels L(make_laplace_domain(GetParam(), 97));
  // Parallel float setup (1 and 2 threads) equals the serial one bitwise.
  for (int threads : {1, 2}) {
    const test::ThreadCountGuard set_threads(threads);
    std::vector<std::vector<float>> p1(8, std::vector<float>(L.coarse.padded_size(), 0.0f)),
        a1(5, std::vector<float>(L.coarse.padded_size(), 0.0f)),
        p2(8, std::vector<float>(L.coarser.padded_size(), 0.0f)),
        a2(5, std::vector<float>(L.coarser.padded_size(), 0.0f));
    build_interpolation_texels(L.fine, L.bits.data(), FloatLevels::P(p1), Execution::parallel);
    galerkin_texels(L.fine, L.bits.data(), FloatLevels::P(p1).view(), FloatLevels::A(a1), Execution::parallel);
    build_interpolation_stencil9(L.coarse, FloatLevels::A(a1).view(), FloatLevels::P(p2), Execution::parallel);
    galerkin_stencil9(L.coarse, FloatLevels::A(a1).view(), FloatLevels::P(p2).view(), FloatLevels::A(a2),
                      Execution::parallel);
    EXPECT_EQ(p1, L.p1) << threads << " threads";
    EXPECT_EQ(a1, L.a1) << threads << " threads";
    EXPECT_EQ(p2, L.p2) << threads << " threads";
    EXPECT_EQ(a2, L.a2) << threads << " threads";
  }
  // The double interpolation rounded: the edge weights (pass 1) exactly, the cell-centre
  // weights (pass 2, formed from the rounded edge weights) to float precision.
  std::vector<std::vector<double>> pd(8, std::vector<double>(L.coarse.padded_size(), 0.0));
  const InterpolationArrays P{pd[0].data(), pd[1].data(), pd[2].data(), pd[3].data(),
                              pd[4].data(), pd[5].data(), pd[6].data(), pd[7].data()};
  build_interpolation_texels(L.fine, L.bits.data(), P, Execution::serial);
  for (int k = 0; k < 8; ++k)
    for (std::size_t t = 0; t < pd[k].size(); ++t) {
      if (k < 4)
        EXPECT_EQ(L.p1[k][t], static_cast<float>(pd[k][t])) << "weight " << k << " at " << t;
      else
        EXPECT_NEAR(L.p1[k][t], pd[k][t], 2e-7) << "weight " << k << " at " << t;
    }
  // The float Galerkin operator is the double product of the float interpolation, rounded.
  std::vector<std::vector<double>> p1d(8), ad(5, std::vector<double>(L.coarse.padded_size(), 0.0));
  for (int k = 0; k < 8; ++k) p1d[k].assign(L.p1[k].begin(), L.p1[k].end());
  galerkin_texels(L.fine, L.bits.data(),
                  InterpolationView{p1d[0].data(), p1d[1].data(), p1d[2].data(), p1d[3].data(), p1d[4].data(),
                                    p1d[5].data(), p1d[6].data(), p1d[7].data()},
                  Stencil9Arrays{ad[0].data(), ad[1].data(), ad[2].data(), ad[3].data(), ad[4].data()},
                  Execution::serial);
  for (int k = 0; k < 5; ++k) EXPECT_EQ(std::vector<float>(ad[k].begin(), ad[k].end()), L.a1[k]) << "array " << k;
}

// The float cycle is a preconditioner only: the outer CG in double reaches the same
// tolerances in the same iterations as with the double cycle, 1e-11 included (the agreement
// with CHOLMOD in test_multigrid_convergence), and the solve does not depend on the threads.
TEST_P(MultigridSinglePrecision, SolvesMatchTheDoubleCycleAndDirectSolution) {
  const TexelTile problem = make_laplace_domain(GetParam(), 160);
  TexelTile direct = problem;
  solve_laplace_direct(direct);
  for (double tolerance : {1e-6, 1e-11}) {
    LaplaceMultigridOptions options;
    options.warm_start = false;
    options.tolerance = tolerance;
    TexelTile single = problem, twice = problem;
    options.single_precision_min_texels = 1l << 40;  // double cycle
    const LaplaceSolveStats reference = solve_laplace_multigrid(twice, options);
    options.single_precision_min_texels = 0;  // float cycle
    const LaplaceSolveStats stats = solve_laplace_multigrid(single, options);
    EXPECT_LE(stats.relative_residual, tolerance);
    EXPECT_LE(stats.iterations, reference.iterations) << "tolerance " << tolerance;
    if (tolerance < 1e-10) {
      double largest = 0;
      for (std::size_t k = 0; k < direct.values.size(); ++k)
        if (std::isfinite(direct.values[k])) largest = std::max(largest, std::abs(single.values[k] - direct.values[k]));
      EXPECT_LT(largest, 1e-8);
    }
    TexelTile one = problem, serial = problem;
    test::with_threads(1, [&] { solve_laplace_multigrid(one, options); });
    options.execution = Execution::serial;
    solve_laplace_multigrid(serial, options);
    EXPECT_EQ(one.values, single.values);
    EXPECT_EQ(serial.values, single.values);
  }
}

// The float arrays come from the block cache unzeroed too (frame_zeroed_float_buffer): with
// poisoned (NaN) blocks the float-cycle solves must be bitwise those from zeroed blocks.
TEST_P(MultigridSinglePrecision, PoisonedFloatBlocksGiveTheSameSolution) {
  const TexelTile problem = make_laplace_domain(GetParam(), 384);  // level-1 float arrays: cached blocks
  LaplaceMultigridOptions options;
  options.single_precision_min_texels = 0;
  TexelTile clean = problem, poisoned = problem;
  solve_laplace_multigrid(clean, options);  // also leaves dirty blocks in the cache
  detail::set_poison_unzeroed_blocks(true);
  solve_laplace_multigrid(poisoned, options);
  detail::set_poison_unzeroed_blocks(false);
  EXPECT_EQ(clean.values, poisoned.values);
}

INSTANTIATE_TEST_SUITE_P(Domains, MultigridSinglePrecision,
                         ::testing::Values(LaplaceDomain::open, LaplaceDomain::slit, LaplaceDomain::spiral,
                                           LaplaceDomain::accordion, LaplaceDomain::chad, LaplaceDomain::one_ring),
                         [](const ::testing::TestParamInfo<LaplaceDomain>& info) { return laplace_domain_name(info.param); });

}  // namespace
}  // namespace dgtex
