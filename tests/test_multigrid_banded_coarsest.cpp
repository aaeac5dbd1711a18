// The band Cholesky of the multigrid's coarsest level (runtime/banded_cholesky.h): its
// bandwidth, solutions against Eigen's sparse LLT, a non-positive pivot reported, and the
// spiral at T = 256 (coarsening stops at 32 x 32 nodes, factored in band form) solved like
// CHOLMOD does. Also where coarsening stops: not at a large level for one isolated orphan.
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/SparseCholesky>

#include "banded_cholesky.h"  // internal (runtime/)
#include "dgtex/laplace_domains.h"
#include "dgtex/laplace_multigrid.h"
#include "dgtex/laplace_solver.h"

namespace dgtex {
namespace {
using kernels::TexelTile;

// A 9-point operator on an nx x ny grid with random positive weights, numbered row by row:
// bandwidth nx + 1; diagonally dominant, so SPD.
Eigen::SparseMatrix<double> grid_operator(int nx, int ny, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> w(0.1, 1.0);
  std::vector<Eigen::Triplet<double>> entries;
  std::vector<double> diagonal(static_cast<std::size_t>(nx) * ny, 1e-3);
  auto couple = [&](int a, int b) {
    const double v = w(rng);
    entries.emplace_back(a, b, -v);
    entries.emplace_back(b, a, -v);
    diagonal[a] += v;
    diagonal[b] += v;
  };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int k = j * nx + i;
      if (i + 1 < nx) couple(k, k + 1);
      if (j + 1 < ny) couple(k, k + nx);
      if (i + 1 < nx && j + 1 < ny) couple(k, k + nx + 1);
      if (i > 0 && j + 1 < ny) couple(k, k + nx - 1);
    }
  for (std::size_t k = 0; k < diagonal.size(); ++k) entries.emplace_back(k, k, diagonal[k]);
  Eigen::SparseMatrix<double> a(nx * ny, nx * ny);
  a.setFromTriplets(entries.begin(), entries.end());
  return a;
}

TEST(BandedCholesky, SolvesLikeSparseLltAndReportsTheBand) {
  for (auto [nx, ny] : {std::pair{32, 32}, std::pair{7, 40}, std::pair{1, 5}}) {
    const Eigen::SparseMatrix<double> a = grid_operator(nx, ny, 7u + nx);
    EXPECT_EQ(detail::BandedCholesky::bandwidth(a), nx == 1 ? 1 : nx + 1);
    detail::BandedCholesky band;
    ASSERT_TRUE(band.factorize(a));
    Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(nx * ny, -1.0, 2.0), x;
    band.solve(b, x);
    Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> llt(a);
    const Eigen::VectorXd reference = llt.solve(b);
    EXPECT_LT((x - reference).norm(), 1e-12 * reference.norm()) << nx << " x " << ny;
    EXPECT_LT((a * x - b).norm(), 1e-12 * b.norm());
  }
}

TEST(BandedCholesky, NonPositivePivotIsReported) {
  Eigen::SparseMatrix<double> a = grid_operator(5, 5, 3u);
  a.coeffRef(12, 12) = -1.0;  // an indefinite diagonal entry
  detail::BandedCholesky band;
  EXPECT_FALSE(band.factorize(a));
}

TEST(BandedCholesky, SpiralCoarsestLevelGivesCholmodsSolution) {
  // Spiral T = 256: coarsening stops at level 3 (32 x 32 > 400 unknowns: the band factor).
  TexelTile tile = make_laplace_domain(LaplaceDomain::spiral, 256), direct = tile;
  EXPECT_EQ(LaplaceMultigrid(tile).level_count(), 4);
  LaplaceMultigridOptions options;
  options.tolerance = 1e-11;
  std::vector<double> one_thread;
  for (int threads : {1, 2}) {
    omp_set_num_threads(threads);
    TexelTile solved = tile;
    solve_laplace_multigrid(solved, options);
    if (threads == 2) {
      EXPECT_EQ(solved.values, one_thread);  // independent of the thread count
      continue;
    }
    one_thread = solved.values;
    solve_laplace(direct, LaplaceSolver::cholmod);
    double diff = 0, norm = 0;
    for (std::size_t k = 0; k < solved.values.size(); ++k) {
      diff = std::max(diff, std::abs(solved.values[k] - direct.values[k]));
      norm = std::max(norm, std::abs(direct.values[k]));
    }
    EXPECT_LT(diff, 1e-8 * norm);
  }
}

TEST(CoarsestLevel, AnIsolatedOrphanDoesNotStopALargeHierarchy) {
  // 256 x 256, 0 at the bottom row, 1 at the top; one texel walled off from its east and
  // west neighbours (coupled north-south only), so the first coarsening gives it no
  // interpolation: one orphan. The texel level is far too large to factor cheaply, and one
  // orphan in 65k nodes is isolated: the hierarchy coarsens on (it used to stop at the
  // texels and factor all 65k of them) and still gives CHOLMOD's answer.
  TexelTile tile(256, 256), direct = tile;
  for (int i = 0; i < 256; ++i) {
    tile.flags[tile.index(i, 0)] |= kernels::dirichlet;
    tile.flags[tile.index(i, 255)] |= kernels::dirichlet;
    tile.values[tile.index(i, 255)] = 1;
  }
  tile.flags[tile.index(100, 100)] |= kernels::wall_east;
  tile.flags[tile.index(101, 100)] |= kernels::wall_east;
  direct = tile;
  EXPECT_GT(LaplaceMultigrid(tile).level_count(), 4);
  LaplaceMultigridOptions options;
  options.tolerance = 1e-10;
  const LaplaceSolveStats stats = solve_laplace_multigrid(tile, options);
  EXPECT_LE(stats.iterations, 12);
  solve_laplace(direct, LaplaceSolver::cholmod);
  double diff = 0;
  for (std::size_t k = 0; k < tile.values.size(); ++k) diff = std::max(diff, std::abs(tile.values[k] - direct.values[k]));
  EXPECT_LT(diff, 1e-8);
  // (Many orphans, as in a spiral's channels, still stop coarsening where they appear:
  // test_multigrid_convergence's spiral_128_tri cases fail otherwise.)
}

}  // namespace
}  // namespace dgtex
