// Multigrid kernels: reference vs parallel forms (bitwise), Galerkin operator and
// transfers against explicit sparse matrices, thread-count independence of whole solves.
#include <gtest/gtest.h>
#include <omp.h>

#include <Eigen/SparseCore>
#include <iterator>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>

#include "dgtex/kernels/multigrid_galerkin.h"
#include "dgtex/kernels/multigrid_residual.h"
#include "dgtex/kernels/multigrid_smooth.h"
#include "dgtex/kernels/multigrid_transfer.h"
#include "dgtex/kernels/multigrid_unknowns.h"
#include "dgtex/laplace_direct.h"
#include "dgtex/laplace_domains.h"
#include "dgtex/laplace_multigrid.h"
#include "dgtex/laplace_problem.h"
#include "multigrid_rows.h"  // internal: the row loops and their two forms
#include "thread_count_support.h"

namespace dgtex {
namespace {
using namespace kernels;

// Level 0 and one coarse level of a domain, with random vectors (fixed seed).
struct TwoLevels {
  GridShape fine, coarse;
  std::vector<std::uint8_t> bits;
  std::vector<std::vector<double>> p, a;
  std::vector<double> x, b, xc, bc;
  InterpolationArrays P() { return {p[0].data(), p[1].data(), p[2].data(), p[3].data(), p[4].data(), p[5].data(), p[6].data(), p[7].data()}; }
  Stencil9Arrays A() { return {a[0].data(), a[1].data(), a[2].data(), a[3].data(), a[4].data()}; }

  explicit TwoLevels(const TexelTile& tile) {
    std::vector<std::uint8_t> tile_bits;
    classify_laplace_texels(tile, tile_bits);
    fine = {tile.width, tile.height};
    coarse = fine.coarser();
    bits.assign(fine.padded_size(), 0);
    for (int j = 0; j < fine.ny; ++j)
      for (int i = 0; i < fine.nx; ++i) bits[fine.at(i, j)] = tile_bits[tile.index(i, j)];
    p.assign(8, std::vector<double>(coarse.padded_size(), 0.0));
    a.assign(5, std::vector<double>(coarse.padded_size(), 0.0));
    build_interpolation_texels(fine, bits.data(), P(), Execution::serial);
    galerkin_texels(fine, bits.data(), P().view(), A(), Execution::serial);
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> u(-1, 1);
    auto random_interior = [&](GridShape g) {
      std::vector<double> v(g.padded_size(), 0.0);
      for (int j = 0; j < g.ny; ++j)
        for (int i = 0; i < g.nx; ++i) v[g.at(i, j)] = u(rng);
      return v;
    };
    x = random_interior(fine);
    b = random_interior(fine);
    xc = random_interior(coarse);
    bc = random_interior(coarse);
  }
};

class MultigridKernels : public ::testing::TestWithParam<LaplaceDomain> {};

TEST_P(MultigridKernels, ParallelFormsEqualReferenceBitwise) {
  // Even and uneven splits of the rows among the threads.
  for (int threads : {2, 3}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    const test::ThreadCountGuard set_threads(threads);
    TwoLevels L(make_laplace_domain(GetParam(), 96));
    // Smoothers.
    for (int color = 0; color < 2; ++color) {
      std::vector<double> ref = L.x, par = L.x;
      smooth_texels_color_reference(L.fine, L.bits.data(), L.b.data(), ref.data(), color);
      smooth_texels_color(L.fine, L.bits.data(), L.b.data(), par.data(), color);
      EXPECT_EQ(ref, par);
    }
    for (int color = 0; color < 4; ++color) {
      std::vector<double> ref = L.xc, par = L.xc;
      smooth_stencil9_color_reference(L.coarse, L.A().view(), L.bc.data(), ref.data(), color);
      smooth_stencil9_color(L.coarse, L.A().view(), L.bc.data(), par.data(), color);
      EXPECT_EQ(ref, par);
    }
    // Residuals and their row norms.
    {
      std::vector<double> r1(L.x.size(), 0.0), r2 = r1, n1(L.fine.ny), n2(L.fine.ny);
      residual_texels_reference(L.fine, L.bits.data(), L.b.data(), L.x.data(), r1.data(), n1.data());
      residual_texels(L.fine, L.bits.data(), L.b.data(), L.x.data(), r2.data(), n2.data());
      EXPECT_EQ(r1, r2);
      EXPECT_EQ(n1, n2);
      std::vector<double> c1(L.xc.size(), 0.0), c2 = c1, m1(L.coarse.ny), m2(L.coarse.ny);
      residual_stencil9_reference(L.coarse, L.A().view(), L.bc.data(), L.xc.data(), c1.data(), m1.data());
      residual_stencil9(L.coarse, L.A().view(), L.bc.data(), L.xc.data(), c2.data(), m2.data());
      EXPECT_EQ(c1, c2);
      EXPECT_EQ(m1, m2);
    }
    // Transfers.
    {
      std::vector<double> b1(L.xc.size(), 0.0), b2 = b1;
      restrict_residual_reference(L.fine, L.coarse, L.P().view(), L.x.data(), b1.data());
      restrict_residual(L.fine, L.coarse, L.P().view(), L.x.data(), b2.data());
      EXPECT_EQ(b1, b2);
      std::vector<std::uint8_t> active(L.bits.size());
      for (std::size_t t = 0; t < active.size(); ++t) active[t] = (L.bits[t] & is_unknown) ? 1 : 0;
      std::vector<double> x1 = L.x, x2 = L.x;
      prolong_correction_reference(L.fine, L.coarse, L.P().view(), L.xc.data(), active.data(), x1.data());
      prolong_correction(L.fine, L.coarse, L.P().view(), L.xc.data(), active.data(), x2.data());
      EXPECT_EQ(x1, x2);
    }
    // The level-0 product of conjugate gradients (the seamed patch solves use it).
    {
      std::vector<double> y1(L.x.size(), 0.0), y2 = y1, d1(L.fine.ny), d2(L.fine.ny);
      apply_texels(L.fine, L.bits.data(), L.x.data(), y1.data(), d1.data(), Execution::serial);
      apply_texels(L.fine, L.bits.data(), L.x.data(), y2.data(), d2.data(), Execution::parallel);
      EXPECT_EQ(y1, y2);
      EXPECT_EQ(d1, d2);
    }
    // Setup kernels: serial and parallel forms.
    {
      TwoLevels M(make_laplace_domain(GetParam(), 96));
      for (auto& v : M.p) std::fill(v.begin(), v.end(), 0.0);
      for (auto& v : M.a) std::fill(v.begin(), v.end(), 0.0);
      build_interpolation_texels(M.fine, M.bits.data(), M.P(), Execution::parallel);
      galerkin_texels(M.fine, M.bits.data(), M.P().view(), M.A(), Execution::parallel);
      EXPECT_EQ(M.p, L.p);
      EXPECT_EQ(M.a, L.a);
    }
  }
}

TEST_P(MultigridKernels, GalerkinAndTransfersMatchExplicitMatrices) {
  TwoLevels L(make_laplace_domain(GetParam(), 64));
  const int nf = L.fine.nx * L.fine.ny, nc = L.coarse.nx * L.coarse.ny;
  std::vector<Eigen::Triplet<double>> ta, tp;
  for (int j = 0; j < L.fine.ny; ++j)
    for (int i = 0; i < L.fine.nx; ++i) {
      const int k = j * L.fine.nx + i;
      const std::uint8_t m = L.bits[L.fine.at(i, j)];
      if (!(m & is_unknown)) continue;
      ta.emplace_back(k, k, laplace_degree(m));
      if (m & couples_west_unknown) ta.emplace_back(k, k - 1, -1.0);
      if (m & couples_east_unknown) ta.emplace_back(k, k + 1, -1.0);
      if (m & couples_south_unknown) ta.emplace_back(k, k - L.fine.nx, -1.0);
      if (m & couples_north_unknown) ta.emplace_back(k, k + L.fine.nx, -1.0);
    }
  for (int j = 0; j < L.fine.ny; ++j)
    for (int i = 0; i < L.fine.nx; ++i) {
      const int k = j * L.fine.nx + i, I = i / 2, J = j / 2;
      const std::int64_t c = L.coarse.at(I, J);
      auto add = [&](int a, int b, double w) {
        if (a < L.coarse.nx && b < L.coarse.ny && w != 0) tp.emplace_back(k, b * L.coarse.nx + a, w);
      };
      if (i % 2 == 0 && j % 2 == 0) add(I, J, 1);
      else if (j % 2 == 0) { add(I, J, L.p[0][c]); add(I + 1, J, L.p[1][c]); }
      else if (i % 2 == 0) { add(I, J, L.p[2][c]); add(I, J + 1, L.p[3][c]); }
      else { add(I, J, L.p[4][c]); add(I + 1, J, L.p[5][c]); add(I, J + 1, L.p[6][c]); add(I + 1, J + 1, L.p[7][c]); }
    }
  Eigen::SparseMatrix<double> A(nf, nf), P(nf, nc);
  A.setFromTriplets(ta.begin(), ta.end());
  P.setFromTriplets(tp.begin(), tp.end());
  const Eigen::SparseMatrix<double> Ac = P.transpose() * A * P;
  const Eigen::MatrixXd dense = Eigen::MatrixXd(Ac);
  for (int J = 0; J < L.coarse.ny; ++J)
    for (int I = 0; I < L.coarse.nx; ++I) {
      const int k = J * L.coarse.nx + I;
      const std::int64_t c = L.coarse.at(I, J);
      auto get = [&](int a, int b) { return (a >= 0 && b < L.coarse.ny && a < L.coarse.nx) ? dense(k, b * L.coarse.nx + a) : 0.0; };
      EXPECT_NEAR(L.a[0][c], get(I, J), 1e-13);
      EXPECT_NEAR(L.a[1][c], get(I + 1, J), 1e-13);
      EXPECT_NEAR(L.a[2][c], get(I, J + 1), 1e-13);
      EXPECT_NEAR(L.a[3][c], get(I + 1, J + 1), 1e-13);
      EXPECT_NEAR(L.a[4][c], get(I - 1, J + 1), 1e-13);
    }
  // Walls stay walls: no coarse coupling between nodes whose columns lie on different sides
  // is implied by the exact match above; check also restriction = P^T and prolongation = P.
  Eigen::VectorXd r(nf), xc(nc);
  std::vector<double> rp(L.fine.padded_size(), 0.0), bc(L.coarse.padded_size(), 0.0), xcp(L.coarse.padded_size(), 0.0),
      xf(L.fine.padded_size(), 0.0);
  std::vector<std::uint8_t> all(L.fine.padded_size(), 0);
  for (int j = 0; j < L.fine.ny; ++j)
    for (int i = 0; i < L.fine.nx; ++i) {
      r[j * L.fine.nx + i] = L.x[L.fine.at(i, j)];
      rp[L.fine.at(i, j)] = L.x[L.fine.at(i, j)];
      all[L.fine.at(i, j)] = 1;
    }
  for (int j = 0; j < L.coarse.ny; ++j)
    for (int i = 0; i < L.coarse.nx; ++i) xc[j * L.coarse.nx + i] = xcp[L.coarse.at(i, j)] = L.xc[L.coarse.at(i, j)];
  restrict_residual(L.fine, L.coarse, L.P().view(), rp.data(), bc.data());
  prolong_correction(L.fine, L.coarse, L.P().view(), xcp.data(), all.data(), xf.data());
  const Eigen::VectorXd restricted = P.transpose() * r, prolonged = P * xc;
  for (int j = 0; j < L.coarse.ny; ++j)
    for (int i = 0; i < L.coarse.nx; ++i) EXPECT_NEAR(bc[L.coarse.at(i, j)], restricted[j * L.coarse.nx + i], 1e-13);
  for (int j = 0; j < L.fine.ny; ++j)
    for (int i = 0; i < L.fine.nx; ++i) EXPECT_NEAR(xf[L.fine.at(i, j)], prolonged[j * L.fine.nx + i], 1e-13);
}

TEST_P(MultigridKernels, SolveIsIndependentOfThreadCount) {
  const TexelTile problem = make_laplace_domain(GetParam(), 96);
  TexelTile one = problem, two = problem, serial = problem;
  LaplaceMultigridOptions options;
  options.warm_start = false;
  test::with_threads(1, [&] { solve_laplace_multigrid(one, options); });
  test::with_threads(2, [&] { solve_laplace_multigrid(two, options); });
  options.execution = Execution::serial;
  solve_laplace_multigrid(serial, options);
  EXPECT_EQ(one.values, two.values);
  EXPECT_EQ(one.values, serial.values);
  // The robust cycle (inner CG on level 1) too.
  TexelTile robust_one = problem, robust_two = problem, robust_serial = problem;
  options.coarse_solve_tolerance = 0.02;
  options.execution = Execution::parallel;
  test::with_threads(1, [&] { solve_laplace_multigrid(robust_one, options); });
  test::with_threads(2, [&] { solve_laplace_multigrid(robust_two, options); });
  options.execution = Execution::serial;
  solve_laplace_multigrid(robust_serial, options);
  EXPECT_EQ(robust_one.values, robust_two.values);
  EXPECT_EQ(robust_one.values, robust_serial.values);
}

TEST_P(MultigridKernels, FusedSweepsEqualColourByColourReference) {
  // Even and uneven splits of the rows among the threads.
  for (int threads : {2, 3}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    const test::ThreadCountGuard set_threads(threads);
    TwoLevels L(make_laplace_domain(GetParam(), 100));  // 100 rows: blocks of 32 plus a partial one
    for (Execution ex : {Execution::serial, Execution::parallel}) {
      for (bool forward : {true, false}) {
        std::vector<double> ref = L.x, fused = L.x;
        smooth_texels_color_reference(L.fine, L.bits.data(), L.b.data(), ref.data(), forward ? 0 : 1);
        smooth_texels_color_reference(L.fine, L.bits.data(), L.b.data(), ref.data(), forward ? 1 : 0);
        smooth_texels_sweep(L.fine, L.bits.data(), L.b.data(), fused.data(), forward, ex);
        EXPECT_EQ(ref, fused);
        std::vector<double> ref9 = L.xc, fused9 = L.xc;
        for (int k = 0; k < 4; ++k)
          smooth_stencil9_color_reference(L.coarse, L.A().view(), L.bc.data(), ref9.data(), forward ? k : 3 - k);
        smooth_stencil9_sweep(L.coarse, L.A().view(), L.bc.data(), fused9.data(), forward, ex);
        EXPECT_EQ(ref9, fused9);
      }
      // From a zero guess: x need not be initialised, non-unknowns end at 0.
      std::vector<double> ref(L.x.size(), 0.0), fused(L.x.size(), 0.0);
      smooth_texels_color_reference(L.fine, L.bits.data(), L.b.data(), ref.data(), 0);
      smooth_texels_color_reference(L.fine, L.bits.data(), L.b.data(), ref.data(), 1);
      for (int j = 0; j < L.fine.ny; ++j)
        for (int i = 0; i < L.fine.nx; ++i) fused[L.fine.at(i, j)] = 7.0;  // garbage in the interior
      smooth_texels_sweep_from_zero(L.fine, L.bits.data(), L.b.data(), fused.data(), ex);
      EXPECT_EQ(ref, fused);
    }
  }
}

TEST_P(MultigridKernels, FusedConjugateGradientStepsEqualReference) {
  // Even and uneven splits of the rows among the threads.
  for (int threads : {2, 3}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    const test::ThreadCountGuard set_threads(threads);
    TwoLevels L(make_laplace_domain(GetParam(), 100));
    const double alpha = 0.37, beta = -0.61;
    for (Execution ex : {Execution::serial, Execution::parallel}) {
      std::vector<double> x1 = L.x, r1 = L.b, z1(L.x.size(), 0.0), n1(L.fine.ny);
      std::vector<double> x2 = L.x, r2 = L.b, z2(L.x.size(), 0.0), n2(L.fine.ny);
      cg_update_and_smooth_texels_from_zero_reference(L.fine, L.bits.data(), alpha, L.x.data(), L.b.data(), x1.data(),
                                                      r1.data(), z1.data(), n1.data());
      cg_update_and_smooth_texels_from_zero(L.fine, L.bits.data(), alpha, L.x.data(), L.b.data(), x2.data(), r2.data(),
                                            z2.data(), n2.data(), ex);
      EXPECT_EQ(x1, x2);
      EXPECT_EQ(r1, r2);
      EXPECT_EQ(z1, z2);
      EXPECT_EQ(n1, n2);
      std::vector<double> p1 = L.x, q1(L.x.size(), 0.0), d1(L.fine.ny), p2 = L.x, q2 = q1, d2(L.fine.ny);
      update_direction_and_apply_texels_reference(L.fine, L.bits.data(), L.b.data(), beta, p1.data(), q1.data(), d1.data());
      update_direction_and_apply_texels(L.fine, L.bits.data(), L.b.data(), beta, p2.data(), q2.data(), d2.data(), ex);
      EXPECT_EQ(p1, p2);
      EXPECT_EQ(q1, q2);
      EXPECT_EQ(d1, d2);
    }
  }
}

// The listed-texel form writes what the whole-grid product writes there, and nothing else.
TEST_P(MultigridKernels, OperatorAtListedTexelsEqualsTheWholeGridProduct) {
  TwoLevels L(make_laplace_domain(GetParam(), 100));
  std::vector<double> whole(L.x.size(), 0.0), rows(L.fine.ny);
  apply_texels(L.fine, L.bits.data(), L.x.data(), whole.data(), rows.data(), Execution::serial);
  std::vector<std::int64_t> listed;
  for (int j = 0; j < L.fine.ny; j += 3)
    for (int i = j % 5; i < L.fine.nx; i += 7) listed.push_back(L.fine.at(i, j));
  const double untouched = -12345.0;
  std::vector<double> at(L.x.size(), untouched);
  apply_texels_at(L.fine, L.bits.data(), L.x.data(), listed.data(), static_cast<std::int64_t>(listed.size()),
                  at.data());
  std::vector<char> is_listed(L.x.size(), 0);
  for (std::int64_t t : listed) is_listed[t] = 1;
  int unknowns_listed = 0;
  for (std::size_t t = 0; t < at.size(); ++t) {
    if (is_listed[t]) {
      EXPECT_EQ(at[t], whole[t]) << "texel " << t;
      unknowns_listed += (L.bits[t] & is_unknown) != 0;
    } else {
      EXPECT_EQ(at[t], untouched) << "texel " << t;
    }
  }
  EXPECT_GT(unknowns_listed, 100);
}

TEST_P(MultigridKernels, RedBlackTransfersMatchReferencesAndFullForms) {
  // Even and uneven splits of the rows among the threads.
  for (int threads : {2, 3}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    const test::ThreadCountGuard set_threads(threads);
    TwoLevels L(make_laplace_domain(GetParam(), 96));
    for (int color = 0; color < 2; ++color) {
      std::vector<double> r1(L.x.size(), 0.0), r2 = r1, full = r1;
      residual_texels_color_reference(L.fine, L.bits.data(), L.b.data(), L.x.data(), r1.data(), color);
      residual_texels_color(L.fine, L.bits.data(), L.b.data(), L.x.data(), r2.data(), color);
      EXPECT_EQ(r1, r2);
      residual_texels_reference(L.fine, L.bits.data(), L.b.data(), L.x.data(), full.data(), nullptr);
      for (int j = 0; j < L.fine.ny; ++j)
        for (int i = 0; i < L.fine.nx; ++i)
          EXPECT_EQ(r1[L.fine.at(i, j)], (i + j) % 2 == color ? full[L.fine.at(i, j)] : 0.0);
    }
    // Restriction of a red-only vector: equal to P^T of that vector (round-off: other order).
    std::vector<double> red = L.x;
    for (int j = 0; j < L.fine.ny; ++j)
      for (int i = 0; i < L.fine.nx; ++i)
        if ((i + j) % 2) red[L.fine.at(i, j)] = 0.0;
    std::vector<double> b1(L.xc.size(), 0.0), b2 = b1, b3 = b1;
    restrict_red_residual_reference(L.fine, L.coarse, L.P().view(), red.data(), b1.data());
    restrict_red_residual(L.fine, L.coarse, L.P().view(), red.data(), b2.data());
    restrict_residual_reference(L.fine, L.coarse, L.P().view(), red.data(), b3.data());
    EXPECT_EQ(b1, b2);
    for (std::size_t t = 0; t < b1.size(); ++t) EXPECT_NEAR(b1[t], b3[t], 1e-13);
    // Red residual and its restriction in one pass: bitwise the two kernels in turn, for odd
    // grid sizes too (cell centres in the ghost row / column).
    for (int size : {96, 75}) {
      TwoLevels M(make_laplace_domain(GetParam(), size));
      std::vector<double> r(M.x.size(), 0.0), two_steps(M.xc.size(), 0.0), ref = two_steps, fused = two_steps;
      residual_texels_color(M.fine, M.bits.data(), M.b.data(), M.x.data(), r.data(), 0);
      restrict_red_residual(M.fine, M.coarse, M.P().view(), r.data(), two_steps.data());
      restrict_red_residual_texels_reference(M.fine, M.coarse, M.P().view(), M.bits.data(), M.b.data(), M.x.data(),
                                             ref.data());
      restrict_red_residual_texels(M.fine, M.coarse, M.P().view(), M.bits.data(), M.b.data(), M.x.data(),
                                   fused.data());
      EXPECT_EQ(ref, two_steps);
      EXPECT_EQ(fused, two_steps);
    }
    // Prolongation to red nodes: the full prolongation's values there, black untouched.
    std::vector<std::uint8_t> active(L.bits.size());
    for (std::size_t t = 0; t < active.size(); ++t) active[t] = (L.bits[t] & is_unknown) ? 1 : 0;
    std::vector<double> x1 = L.x, x2 = L.x, x3 = L.x;
    prolong_correction_red_reference(L.fine, L.coarse, L.P().view(), L.xc.data(), active.data(), x1.data());
    prolong_correction_red(L.fine, L.coarse, L.P().view(), L.xc.data(), active.data(), x2.data());
    prolong_correction_reference(L.fine, L.coarse, L.P().view(), L.xc.data(), active.data(), x3.data());
    EXPECT_EQ(x1, x2);
    for (int j = 0; j < L.fine.ny; ++j)
      for (int i = 0; i < L.fine.nx; ++i)
        EXPECT_EQ(x1[L.fine.at(i, j)], (i + j) % 2 == 0 ? x3[L.fine.at(i, j)] : L.x[L.fine.at(i, j)]);
  }
}

TEST_P(MultigridKernels, FastClassificationEqualsFloodFillReference) {
  // Even and uneven splits of the rows among the threads.
  for (int threads : {2, 3}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    const test::ThreadCountGuard set_threads(threads);
    for (TexelElementShape shape : {TexelElementShape::quad, TexelElementShape::tri}) {
      const TexelTile tile = make_laplace_domain(GetParam(), 80, shape);
      std::vector<std::uint8_t> ref, serial, parallel;
      const int zr = classify_laplace_texels_reference(tile, ref);
      EXPECT_EQ(classify_laplace_texels(tile, serial, Execution::serial), zr);
      EXPECT_EQ(classify_laplace_texels(tile, parallel, Execution::parallel), zr);
      EXPECT_EQ(ref, serial);
      EXPECT_EQ(ref, parallel);
      const GridShape g{tile.width, tile.height};
      std::vector<std::uint8_t> padded(g.padded_size(), 0xff);
      EXPECT_EQ(classify_laplace_texels_padded(tile, padded.data()), zr);
      for (int j = -1; j <= g.ny; ++j)
        for (int i = -1; i <= g.nx; ++i) {
          const bool inside = i >= 0 && j >= 0 && i < g.nx && j < g.ny;
          EXPECT_EQ(padded[g.at(i, j)], inside ? ref[tile.index(i, j)] : 0);
        }
    }
  }
}

TEST(MultigridClassification, RandomTilesWithIsolatedComponentsEqualReference) {
  // Random walls, Dirichlet and inactive texels: many components, some without data.
  std::mt19937 rng(7);
  for (int k = 0; k < 300; ++k) {
    TexelTile tile(1 + static_cast<int>(rng() % 37), 1 + static_cast<int>(rng() % 37));
    for (auto& f : tile.flags) {
      f = static_cast<std::uint8_t>(rng() & (wall_east | wall_north));
      if (rng() % 7 == 0) f |= dirichlet;
      if (rng() % 9 == 0) f |= inactive;
    }
    std::vector<std::uint8_t> ref, fast;
    const int zr = classify_laplace_texels_reference(tile, ref);
    EXPECT_EQ(classify_laplace_texels(tile, fast, Execution::serial), zr);
    EXPECT_EQ(ref, fast) << "tile " << k << " (" << tile.width << "x" << tile.height << ")";
  }
}

TEST(MultigridClassification, LargeRandomTilesWithLongRunsEqualReferenceInEveryForm) {
  // Few walls (in segments), sparse Dirichlet texels and inactive blocks: long runs, few
  // components, some without data; widths around the fast form's 16- and 64-texel chunks.
  std::mt19937 rng(11);
  const int widths[] = {1, 2, 3, 15, 16, 17, 18, 31, 33, 63, 64, 65, 66, 100, 127, 128, 129, 130, 191, 257, 300};
  int tiles_with_zeroed = 0;
  for (int k = 0; k < 80; ++k) {
    const int w = widths[k % std::size(widths)], h = 1 + static_cast<int>(rng() % 150);
    TexelTile tile(w, h);
    const int segments = static_cast<int>(rng() % 12);
    for (int s = 0; s < segments; ++s) {  // a wall segment along a row or a column
      const bool vertical = rng() % 2;
      const int i0 = static_cast<int>(rng() % w), j0 = static_cast<int>(rng() % h);
      const int length = 1 + static_cast<int>(rng() % std::max(w, h));
      for (int l = 0; l < length; ++l) {
        const int i = vertical ? i0 : i0 + l, j = vertical ? j0 + l : j0;
        if (i < w && j < h) tile.flags[tile.index(i, j)] |= vertical ? wall_east : wall_north;
      }
    }
    const int blocks = static_cast<int>(rng() % 4);
    for (int b = 0; b < blocks; ++b) {  // an inactive rectangle
      const int i0 = static_cast<int>(rng() % w), j0 = static_cast<int>(rng() % h);
      const int bw = 1 + static_cast<int>(rng() % 20), bh = 1 + static_cast<int>(rng() % 20);
      for (int j = j0; j < std::min(h, j0 + bh); ++j)
        for (int i = i0; i < std::min(w, i0 + bw); ++i) tile.flags[tile.index(i, j)] |= inactive;
    }
    for (auto& f : tile.flags) {
      if (rng() % 400 == 0) f |= dirichlet;
      if (rng() % 300 == 0) f |= inactive;
    }
    std::vector<std::uint8_t> ref, serial;
    const int zr = classify_laplace_texels_reference(tile, ref);
    tiles_with_zeroed += zr > 0;
    EXPECT_EQ(classify_laplace_texels(tile, serial, Execution::serial), zr);
    EXPECT_EQ(ref, serial) << "tile " << k << " (" << w << "x" << h << ")";
    for (int threads : {2, 3}) {
      const test::ThreadCountGuard set_threads(threads);
      std::vector<std::uint8_t> parallel(7, 0xff);  // resized (not cleared) by the kernel
      EXPECT_EQ(classify_laplace_texels(tile, parallel, Execution::parallel), zr);
      EXPECT_EQ(ref, parallel) << "tile " << k << ", " << threads << " threads";
      const GridShape g{w, h};
      std::vector<std::uint8_t> padded(g.padded_size(), 0xff);
      EXPECT_EQ(classify_laplace_texels_padded(tile, padded.data(), Execution::parallel), zr);
      for (int j = -1; j <= h; ++j)
        for (int i = -1; i <= w; ++i) {
          const bool inside = i >= 0 && j >= 0 && i < w && j < h;
          ASSERT_EQ(padded[g.at(i, j)], inside ? ref[tile.index(i, j)] : 0) << "tile " << k << " at " << i << "," << j;
        }
    }
  }
  // Both kinds of tile occur: with and without components lacking data.
  EXPECT_GT(tiles_with_zeroed, 10);
  EXPECT_LT(tiles_with_zeroed, 70);
}

TEST(LaplaceTileValidation, NamesTheFirstDirichletTexelWithANonFiniteValue) {
  // Widths that are and are not multiples of the validation's 8-texel groups.
  for (int w : {3, 8, 13}) {
    TexelTile tile(w, 5);
    for (int j = 0; j < 5; ++j) tile.flags[tile.index(w - 1, j)] |= dirichlet;
    tile.values[tile.index(1, 1)] = std::numeric_limits<double>::quiet_NaN();  // not Dirichlet: fine
    EXPECT_NO_THROW(validate_laplace_tile(tile));
    for (double bad : {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
                       std::numeric_limits<double>::quiet_NaN()})
      for (int j : {4, 2}) {  // the last texel of the tile, then one before it: the first is named
        TexelTile broken = tile;
        broken.values[broken.index(w - 1, j)] = bad;
        if (j == 2) broken.values[broken.index(w - 1, 4)] = bad;
        try {
          validate_laplace_tile(broken);
          ADD_FAILURE() << "no exception for width " << w << ", row " << j;
        } catch (const std::invalid_argument& e) {
          EXPECT_EQ(std::string(e.what()), "Laplace solve: Dirichlet texel " + std::to_string(w - 1) + "," +
                                               std::to_string(j) + " has a non-finite value");
        }
      }
  }
}

// The row loops behind the level-0, 9-point and transfer kernels have a baseline (SSE2) and an AVX2
// form, and the level-0 loops that read flag bytes an AVX-512 form (multigrid_rows.h); the
// parallel-vs-reference tests above run the form this machine picks, this one checks every
// form this machine runs gives the baseline's bits, row by row, with a partial group at the
// end of every row (width 101).
TEST_P(MultigridKernels, RowLoopFormsAgreeBitwise) {
  if (!kernels::detail::avx2_supported()) GTEST_SKIP() << "no AVX2: only the baseline form runs here";
  TwoLevels L(make_laplace_domain(GetParam(), 101));
  std::vector<const kernels::detail::TexelRowKernels*> forms = {&kernels::detail::texel_rows(kernels::detail::RowPath::baseline),
                                                       &kernels::detail::texel_rows(kernels::detail::RowPath::avx2)};
  if (kernels::detail::avx512_supported()) forms.push_back(&kernels::detail::texel_rows(kernels::detail::RowPath::avx512));
  const std::uint8_t* bits = L.bits.data();
  std::vector<double> out[3], sums[3];
  // Runs `body(form, out, sums)` for every form from the same inputs and compares.
  auto compare = [&](const char* what, auto body) {
    for (std::size_t f = 0; f < forms.size(); ++f) {
      out[f] = L.x;
      sums[f].assign(L.fine.ny, 0.0);
      body(*forms[f], out[f], sums[f]);
    }
    for (std::size_t f = 1; f < forms.size(); ++f) {
      EXPECT_EQ(out[0], out[f]) << what << ", form " << f;
      EXPECT_EQ(sums[0], sums[f]) << what << ", form " << f;
    }
  };
  const GridShape g = L.fine;
  for (int color = 0; color < 2; ++color) {
    compare("smooth_color", [&](const auto& k, auto& x, auto&) {
      for (int j = 0; j < g.ny; ++j) k.smooth_color(g, bits, L.b.data(), x.data(), j, color);
    });
    // The lagged sweep of lagged_rows with the fused pair, against the two colours one after
    // the other (the same bits: red-black updates of one colour are independent).
    std::vector<double> two_passes = L.x;
    for (int pass = 0; pass < 2; ++pass)
      for (int j = 0; j < g.ny; ++j)
        forms[0]->smooth_color(g, bits, L.b.data(), two_passes.data(), j, pass == 0 ? color : 1 - color);
    compare("smooth_color_pair", [&](const auto& k, auto& x, auto&) {
      k.smooth_color(g, bits, L.b.data(), x.data(), 0, color);
      for (int j = 1; j < g.ny; ++j) k.smooth_color_pair(g, bits, L.b.data(), x.data(), j, color);
      k.smooth_color(g, bits, L.b.data(), x.data(), g.ny - 1, 1 - color);
    });
    EXPECT_EQ(out[0], two_passes) << "smooth_color_pair, colour " << color;
    compare("residual_color", [&](const auto& k, auto& r, auto&) {
      for (int j = 0; j < g.ny; ++j) k.residual_color(g, bits, L.b.data(), L.x.data(), r.data(), j, color);
    });
  }
  compare("red_from_zero", [&](const auto& k, auto& x, auto&) {
    for (int j = 0; j < g.ny; ++j) k.red_from_zero(g, bits, L.b.data(), x.data(), j);
  });
  std::vector<double> from_zero = L.x;
  for (int j = 0; j < g.ny; ++j) forms[0]->red_from_zero(g, bits, L.b.data(), from_zero.data(), j);
  for (int j = 0; j < g.ny; ++j) forms[0]->smooth_color(g, bits, L.b.data(), from_zero.data(), j, 1);
  compare("red_from_zero_pair", [&](const auto& k, auto& x, auto&) {
    k.red_from_zero(g, bits, L.b.data(), x.data(), 0);
    for (int j = 1; j < g.ny; ++j) k.red_from_zero_pair(g, bits, L.b.data(), x.data(), j);
    k.smooth_color(g, bits, L.b.data(), x.data(), g.ny - 1, 1);
  });
  EXPECT_EQ(out[0], from_zero) << "red_from_zero_pair";
  compare("residual", [&](const auto& k, auto& r, auto& n) {
    for (int j = 0; j < g.ny; ++j) n[j] = k.residual(g, bits, L.b.data(), L.x.data(), r.data(), j);
  });
  compare("apply", [&](const auto& k, auto& y, auto& d) {
    for (int j = 0; j < g.ny; ++j) d[j] = k.apply(g, bits, L.x.data(), y.data(), j);
  });
  compare("dot", [&](const auto& k, auto&, auto& d) {
    for (int j = 0; j < g.ny; ++j) d[j] = k.dot(g, L.b.data(), L.x.data(), j);
  });
  compare("cg_update", [&](const auto& k, auto& x, auto& n) {
    std::vector<double> r = L.b;
    for (int j = 0; j < g.ny; ++j) n[j] = k.cg_update(g, 0.37, L.b.data(), L.x.data(), x.data(), r.data(), j);
    x.insert(x.end(), r.begin(), r.end());
  });
  compare("direction", [&](const auto& k, auto& p, auto&) {
    for (int j = 0; j < g.ny; ++j) k.direction(g, L.b.data(), -0.61, p.data(), j);
  });
  // 9-point rows, double and float.
  const GridShape c = L.coarse;
  for (int f = 0; f < 2; ++f) {
    const auto path = f == 0 ? kernels::detail::RowPath::baseline : kernels::detail::RowPath::avx2;
    out[f] = L.xc;
    sums[f] = std::vector<double>(L.xc.size(), 0.0);
    const auto& rows = kernels::detail::stencil9_rows<double>(path);
    for (int ci = 0; ci < 2; ++ci)
      for (int j = 0; j < c.ny; ++j) rows.smooth_color(c, L.A().view(), L.bc.data(), out[f].data(), j, ci);
    for (int j = 0; j < c.ny; ++j) rows.residual(c, L.A().view(), L.bc.data(), L.xc.data(), sums[f].data(), j);
  }
  EXPECT_EQ(out[0], out[1]);
  EXPECT_EQ(sums[0], sums[1]);
  auto to_float = [](const std::vector<double>& v) { return std::vector<float>(v.begin(), v.end()); };
  std::vector<std::vector<float>> af;
  for (const auto& v : L.a) af.push_back(to_float(v));
  const Stencil9ViewFloat a_float{af[0].data(), af[1].data(), af[2].data(), af[3].data(), af[4].data()};
  const std::vector<float> bf = to_float(L.bc);
  std::vector<float> xf[2], rf[2];
  for (int f = 0; f < 2; ++f) {
    const auto path = f == 0 ? kernels::detail::RowPath::baseline : kernels::detail::RowPath::avx2;
    xf[f] = to_float(L.xc);
    rf[f].assign(L.xc.size(), 0.0f);
    const auto& rows = kernels::detail::stencil9_rows<float>(path);
    for (int ci = 0; ci < 2; ++ci)
      for (int j = 0; j < c.ny; ++j) rows.smooth_color(c, a_float, bf.data(), xf[f].data(), j, ci);
    for (int j = 0; j < c.ny; ++j) rows.residual(c, a_float, bf.data(), xf[f].data(), rf[f].data(), j);
  }
  EXPECT_EQ(xf[0], xf[1]);
  EXPECT_EQ(rf[0], rf[1]);
  // Level-0 transfers and the 9-point prolongation (here on level 0's grid and P), with the
  // coarse level in double and in float.
  std::vector<std::uint8_t> active(L.bits.size());
  for (std::size_t t = 0; t < active.size(); ++t) active[t] = (L.bits[t] & is_unknown) ? 1 : 0;
  std::vector<std::vector<float>> pf;
  for (const auto& v : L.p) pf.push_back(to_float(v));
  const InterpolationViewFloat p_float{pf[0].data(), pf[1].data(), pf[2].data(), pf[3].data(),
                                       pf[4].data(), pf[5].data(), pf[6].data(), pf[7].data()};
  const std::vector<float> xcf = to_float(L.xc);
  std::vector<double> bc[2], xd[2], x9[2];
  std::vector<float> bcf[2], x9f[2];
  for (int f = 0; f < 2; ++f) {
    const auto path = f == 0 ? kernels::detail::RowPath::baseline : kernels::detail::RowPath::avx2;
    const auto& transfer = kernels::detail::texel_transfer_rows<double>(path);
    const auto& transfer_float = kernels::detail::texel_transfer_rows<float>(path);
    bc[f].assign(L.xc.size(), 0.0);
    bcf[f].assign(L.xc.size(), 0.0f);
    xd[f] = L.x;
    x9[f] = L.x;
    x9f[f] = to_float(L.x);
    std::vector<double> x_from_float = L.x;
    for (int J = 0; J < c.ny; ++J) {
      transfer.red_residual_restricted(g, c, L.P().view(), bits, L.b.data(), L.x.data(), bc[f].data(), J);
      transfer_float.red_residual_restricted(g, c, p_float, bits, L.b.data(), L.x.data(), bcf[f].data(), J);
    }
    for (int j = 0; j < g.ny; ++j) {
      transfer.prolong_correction_red(g, c, L.P().view(), L.xc.data(), active.data(), xd[f].data(), j);
      transfer_float.prolong_correction_red(g, c, p_float, xcf.data(), active.data(), x_from_float.data(), j);
      kernels::detail::stencil9_rows<double>(path).prolong_correction(g, c, L.P().view(), L.xc.data(), active.data(),
                                                              x9[f].data(), j);
      kernels::detail::stencil9_rows<float>(path).prolong_correction(g, c, p_float, xcf.data(), active.data(), x9f[f].data(),
                                                             j);
    }
    xd[f].insert(xd[f].end(), x_from_float.begin(), x_from_float.end());
  }
  EXPECT_EQ(bc[0], bc[1]);
  EXPECT_EQ(bcf[0], bcf[1]);
  EXPECT_EQ(xd[0], xd[1]);
  EXPECT_EQ(x9[0], x9[1]);
  EXPECT_EQ(x9f[0], x9f[1]);
}

// The fused row pairs against the two calls they replace, at widths below one group of 8,
// of whole groups and with partial groups, on a tile with walls and Dirichlet texels.
TEST(MultigridRowPairs, GiveTheTwoCallsBitsAtEveryWidth) {
  std::vector<const kernels::detail::TexelRowKernels*> forms = {&kernels::detail::texel_rows(kernels::detail::RowPath::baseline)};
  if (kernels::detail::avx2_supported()) forms.push_back(&kernels::detail::texel_rows(kernels::detail::RowPath::avx2));
  if (kernels::detail::avx512_supported()) forms.push_back(&kernels::detail::texel_rows(kernels::detail::RowPath::avx512));
  for (int w : {5, 8, 13, 16, 24, 37}) {
    TexelTile tile(w, 11);
    for (int j = 0; j < 11; ++j) {
      tile.flags[tile.index(0, j)] |= kernels::dirichlet;
      tile.values[tile.index(0, j)] = 1.0;
    }
    for (int i = 1; i < w - 1; ++i) tile.flags[tile.index(i, 5)] |= kernels::wall_north;  // a cut across
    for (int j = 2; j < 9; ++j) tile.flags[tile.index(w / 2, j)] |= kernels::wall_east;
    TwoLevels L(tile);
    const GridShape g = L.fine;
    const std::uint8_t* bits = L.bits.data();
    for (int color = 0; color < 2; ++color) {
      std::vector<double> two_calls = L.x;
      for (int j = 0; j < g.ny; ++j) forms[0]->smooth_color(g, bits, L.b.data(), two_calls.data(), j, color);
      for (int j = 0; j < g.ny; ++j) forms[0]->smooth_color(g, bits, L.b.data(), two_calls.data(), j, 1 - color);
      for (const auto* k : forms) {
        std::vector<double> x = L.x;
        k->smooth_color(g, bits, L.b.data(), x.data(), 0, color);
        for (int j = 1; j < g.ny; ++j) k->smooth_color_pair(g, bits, L.b.data(), x.data(), j, color);
        k->smooth_color(g, bits, L.b.data(), x.data(), g.ny - 1, 1 - color);
        EXPECT_EQ(x, two_calls) << "smooth_color_pair, width " << w << ", colour " << color;
      }
    }
    std::vector<double> two_calls = L.x;
    for (int j = 0; j < g.ny; ++j) forms[0]->red_from_zero(g, bits, L.b.data(), two_calls.data(), j);
    for (int j = 0; j < g.ny; ++j) forms[0]->smooth_color(g, bits, L.b.data(), two_calls.data(), j, 1);
    for (const auto* k : forms) {
      std::vector<double> x = L.x;
      k->red_from_zero(g, bits, L.b.data(), x.data(), 0);
      for (int j = 1; j < g.ny; ++j) k->red_from_zero_pair(g, bits, L.b.data(), x.data(), j);
      k->smooth_color(g, bits, L.b.data(), x.data(), g.ny - 1, 1);
      EXPECT_EQ(x, two_calls) << "red_from_zero_pair, width " << w;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Domains, MultigridKernels,
                         ::testing::Values(LaplaceDomain::open, LaplaceDomain::slit, LaplaceDomain::spiral,
                                           LaplaceDomain::accordion, LaplaceDomain::chad),
                         [](const ::testing::TestParamInfo<LaplaceDomain>& info) { return laplace_domain_name(info.param); });

}  // namespace
}  // namespace dgtex
