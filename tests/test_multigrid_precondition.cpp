// LaplaceMultigrid::precondition (z = M r, one V-cycle of the CG preconditioner) for callers
// that precondition a related operator: M must be symmetric, give the solver's own
// convergence when used in a CG on the tile's operator, and not depend on the threads.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <random>
#include <vector>

#include "dgtex/kernels/multigrid_unknowns.h"
#include "dgtex/laplace_domains.h"
#include "dgtex/laplace_multigrid.h"
#include "thread_count_support.h"

namespace dgtex {
namespace {

// The tile's texel Laplacian on its unknowns: y = A x (Dirichlet texels count as 0).
struct TileOperator {
  int w = 0, h = 0;
  std::vector<std::uint8_t> bits;
  explicit TileOperator(const kernels::TexelTile& tile) : w(tile.width), h(tile.height) {
    kernels::classify_laplace_texels(tile, bits);
  }
  bool unknown(int t) const { return bits[t] & kernels::is_unknown; }
  std::vector<double> apply(const std::vector<double>& x) const {
    std::vector<double> y(x.size(), 0.0);
    for (int t = 0; t < w * h; ++t) {
      const std::uint8_t m = bits[t];
      if (!(m & kernels::is_unknown)) continue;
      double v = kernels::laplace_degree(m) * x[t];
      if (m & kernels::couples_west_unknown) v -= x[t - 1];
      if (m & kernels::couples_east_unknown) v -= x[t + 1];
      if (m & kernels::couples_south_unknown) v -= x[t - w];
      if (m & kernels::couples_north_unknown) v -= x[t + w];
      y[t] = v;
    }
    return y;
  }
};

double dot(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

std::vector<double> random_on_unknowns(const TileOperator& op, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<double> r(static_cast<std::size_t>(op.w) * op.h, 0.0);
  for (int t = 0; t < op.w * op.h; ++t)
    if (op.unknown(t)) r[t] = u(rng);
  return r;
}

class MultigridPrecondition : public ::testing::TestWithParam<LaplaceDomain> {};

TEST_P(MultigridPrecondition, IsSymmetricAndZeroOffTheUnknowns) {
  const kernels::TexelTile tile = make_laplace_domain(GetParam(), 64);
  const TileOperator op(tile);
  LaplaceMultigrid multigrid(tile);
  const std::vector<double> r1 = random_on_unknowns(op, 1), r2 = random_on_unknowns(op, 2);
  std::vector<double> z1, z2;
  multigrid.precondition(r1, z1);
  multigrid.precondition(r2, z2);
  const double a = dot(z1, r2), b = dot(r1, z2);
  EXPECT_NEAR(a, b, 1e-12 * std::abs(a));
  EXPECT_GT(dot(z1, r1), 0.0);
  for (int t = 0; t < op.w * op.h; ++t) {
    EXPECT_EQ(multigrid.is_unknown(t), op.unknown(t));
    if (!op.unknown(t)) {
      EXPECT_EQ(z1[t], 0.0);
    }
  }
}

TEST_P(MultigridPrecondition, CgOnTheTileOperatorConvergesLikeSolve) {
  kernels::TexelTile tile = make_laplace_domain(GetParam(), 128);
  const TileOperator op(tile);
  LaplaceMultigrid multigrid(tile);
  // b = the Dirichlet neighbours' values (the problem solve() solves), x0 = 0.
  std::vector<double> b(tile.values.size(), 0.0);
  for (int j = 0; j < op.h; ++j)
    for (int i = 0; i < op.w; ++i) {
      const int t = tile.index(i, j);
      if (!op.unknown(t)) continue;
      auto add = [&](bool coupled, int n) {
        if (coupled && (tile.flags[n] & kernels::dirichlet) && !(tile.flags[n] & kernels::inactive)) b[t] += tile.values[n];
      };
      add(i > 0 && kernels::texels_coupled_east(tile, i - 1, j), t - 1);
      add(i + 1 < op.w && kernels::texels_coupled_east(tile, i, j), t + 1);
      add(j > 0 && kernels::texels_coupled_north(tile, i, j - 1), t - op.w);
      add(j + 1 < op.h && kernels::texels_coupled_north(tile, i, j), t + op.w);
    }
  const double b_norm = std::sqrt(dot(b, b));
  ASSERT_GT(b_norm, 0.0);
  std::vector<double> x(b.size(), 0.0), r = b, z, p, q;
  multigrid.precondition(r, z);
  p = z;
  double rz = dot(r, z);
  int iterations = 0;
  while (std::sqrt(dot(r, r)) > 1e-6 * b_norm && iterations < 30) {
    q = op.apply(p);
    const double alpha = rz / dot(p, q);
    for (std::size_t k = 0; k < x.size(); ++k) x[k] += alpha * p[k], r[k] -= alpha * q[k];
    ++iterations;
    multigrid.precondition(r, z);
    const double rz_next = dot(r, z);
    for (std::size_t k = 0; k < x.size(); ++k) p[k] = z[k] + rz_next / rz * p[k];
    rz = rz_next;
  }
  kernels::TexelTile solved = tile;
  for (std::size_t k = 0; k < solved.values.size(); ++k)
    if (!(solved.flags[k] & kernels::dirichlet)) solved.values[k] = 0;
  const LaplaceSolveStats stats = multigrid.solve(solved);
  EXPECT_LE(iterations, stats.iterations + 1);
  double difference = 0, norm = 0;
  for (int t = 0; t < op.w * op.h; ++t)
    if (op.unknown(t)) difference += std::pow(x[t] - solved.values[t], 2), norm += std::pow(solved.values[t], 2);
  EXPECT_LT(std::sqrt(difference / norm), 1e-5);
}

TEST_P(MultigridPrecondition, DoesNotDependOnTheThreadCount) {
  // T = 512: level 0 runs parallel under any wait policy, and levels >= 1 in float.
  const kernels::TexelTile tile = make_laplace_domain(GetParam(), 512);
  const TileOperator op(tile);
  const std::vector<double> r = random_on_unknowns(op, 3);
  std::vector<std::vector<double>> z(3);
  const int threads[3] = {1, 2, 4};
  for (int k = 0; k < 3; ++k) {
    const test::ThreadCountGuard set_threads(threads[k]);
    LaplaceMultigrid multigrid(tile);
    multigrid.precondition(r, z[k]);
  }
  EXPECT_EQ(z[0], z[1]);
  EXPECT_EQ(z[0], z[2]);
}

INSTANTIATE_TEST_SUITE_P(Domains, MultigridPrecondition,
                         ::testing::Values(LaplaceDomain::open, LaplaceDomain::slit, LaplaceDomain::spiral,
                                           LaplaceDomain::chad),
                         [](const auto& info) { return laplace_domain_name(info.param); });

TEST(MultigridPreconditionErrors, RejectsAWrongSizeAndTheRobustCycle) {
  const kernels::TexelTile tile = make_laplace_domain(LaplaceDomain::slit, 32);
  LaplaceMultigrid multigrid(tile);
  std::vector<double> z;
  EXPECT_THROW(multigrid.precondition(std::vector<double>(10, 1.0), z), std::invalid_argument);
  EXPECT_THROW((void)multigrid.is_unknown(32 * 32), std::out_of_range);
  LaplaceMultigridOptions robust;
  robust.coarse_solve_tolerance = 0.02;
  LaplaceMultigrid robust_multigrid(tile, robust);
  EXPECT_THROW(robust_multigrid.precondition(std::vector<double>(32 * 32, 1.0), z), std::logic_error);
}

}  // namespace
}  // namespace dgtex
