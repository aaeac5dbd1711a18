// The band Cholesky of the multigrid's coarsest level (runtime/banded_cholesky.h): its
// bandwidth, solutions against Eigen's sparse LLT, a non-positive pivot reported, and the
// spiral at T = 256 (coarsening stops at 32 x 32 nodes, factored in band form) solved like
// CHOLMOD does. Also where coarsening stops: not at a large level for one isolated orphan.
// Coarsest levels too wide for the band go to CHOLMOD in nested-dissection order
// (runtime/grid_nested_dissection.h): the order, its fill, and combs solved like CHOLMOD,
// also by four threads at once (that factor takes no process-wide lock).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/SparseCholesky>

#include "banded_cholesky.h"         // internal (runtime/)
#include "grid_nested_dissection.h"  // internal (runtime/)
#include "dgtex/laplace_domains.h"
#include "dgtex/laplace_multigrid.h"
#include "dgtex/laplace_solver.h"
#include "thread_count_support.h"

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

// The multigrid (to 1e-11) solves `tile` to CHOLMOD's solution within 1e-8 of its largest
// value, with the same bits on 1 and 2 threads.
void expect_cholmods_solution_on_any_thread_count(const TexelTile& tile, const std::string& label) {
  TexelTile direct = tile;
  solve_laplace(direct, LaplaceSolver::cholmod);
  LaplaceMultigridOptions options;
  options.tolerance = 1e-11;
  std::vector<double> one_thread;
  for (int threads : {1, 2}) {
    const test::ThreadCountGuard set_threads(threads);
    TexelTile solved = tile;
    solve_laplace_multigrid(solved, options);
    if (threads == 2) {
      EXPECT_EQ(solved.values, one_thread) << label;  // independent of the thread count
      continue;
    }
    one_thread = solved.values;
    double diff = 0, norm = 0;
    for (std::size_t k = 0; k < solved.values.size(); ++k) {
      diff = std::max(diff, std::abs(solved.values[k] - direct.values[k]));
      norm = std::max(norm, std::abs(direct.values[k]));
    }
    EXPECT_LT(diff, 1e-8 * norm) << label;
  }
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
  const TexelTile tile = make_laplace_domain(LaplaceDomain::spiral, 256);
  EXPECT_EQ(LaplaceMultigrid(tile).level_count(), 4);
  expect_cholmods_solution_on_any_thread_count(tile, "spiral");
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

// Non-zeros of the Cholesky factor of `a` in the order `perm` (new index of each row).
long factor_nonzeros(const Eigen::SparseMatrix<double>& a, const Eigen::VectorXi& perm) {
  const Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> p(perm);
  const Eigen::SparseMatrix<double> permuted = p * a * p.transpose();
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::NaturalOrdering<int>> llt(permuted);
  EXPECT_EQ(llt.info(), Eigen::Success);
  return static_cast<long>(llt.matrixL().nestedExpression().nonZeros());
}

TEST(GridNestedDissection, OrdersEveryActiveNodeOnceWithLessFillThanAmd) {
  std::mt19937 rng(5);
  for (auto [nx, ny] : {std::pair{97, 33}, std::pair{40, 40}, std::pair{1, 30}, std::pair{30, 1}, std::pair{3, 2}}) {
    const kernels::GridShape g{nx, ny};
    std::vector<std::uint8_t> active(g.padded_size(), 0);
    std::bernoulli_distribution keep(0.9);
    int count = 0;
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) count += active[g.at(i, j)] = keep(rng) ? 1 : 0;
    const std::vector<std::int64_t> order = detail::grid_nested_dissection_order(g, active.data());
    ASSERT_EQ(static_cast<int>(order.size()), count) << nx << " x " << ny;
    std::vector<int> seen(g.padded_size(), 0);
    for (std::int64_t t : order) {
      ASSERT_TRUE(active[t]) << nx << " x " << ny;
      EXPECT_EQ(++seen[t], 1) << nx << " x " << ny;
    }
  }
  // On the whole 97 x 33 grid (the slinky's coarsest level), the factor is no fuller than
  // with AMD's order and far below the band of the row-by-row numbering.
  const int nx = 97, ny = 33;
  const Eigen::SparseMatrix<double> a = grid_operator(nx, ny, 11u);
  const kernels::GridShape g{nx, ny};
  std::vector<std::uint8_t> active(g.padded_size(), 0);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) active[g.at(i, j)] = 1;
  const std::vector<std::int64_t> order = detail::grid_nested_dissection_order(g, active.data());
  Eigen::VectorXi nested(nx * ny), row_by_row(nx * ny);
  for (int k = 0; k < nx * ny; ++k) {
    const std::int64_t t = order[k];
    const int i = static_cast<int>(t % g.stride()) - 1, j = static_cast<int>(t / g.stride()) - 1;
    nested[j * nx + i] = k;
    row_by_row[k] = k;
  }
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> amd(a);
  ASSERT_EQ(amd.info(), Eigen::Success);
  const long fill_amd = static_cast<long>(amd.matrixL().nestedExpression().nonZeros());
  const long fill_nested = factor_nonzeros(a, nested), fill_band = factor_nonzeros(a, row_by_row);
  EXPECT_LE(fill_nested, fill_amd) << "nested " << fill_nested << ", AMD " << fill_amd;
  EXPECT_LT(3 * fill_nested, fill_band) << "nested " << fill_nested << ", row by row " << fill_band;
}

// A W x 64 tile, 0 at the left column and 1 at the right, with walls north of every
// `gap`-th row over the middle columns: channels gap texels high, which coarsening cannot
// represent, so it stops with a wide coarsest level (gap 2: the texels themselves, 12k
// nodes; gap 3: 96 x 32 nodes, as in the slinky) that goes to CHOLMOD.
TexelTile comb(int gap) {
  const int w = 192, h = 64;
  TexelTile tile(w, h);
  for (int j = 0; j < h; ++j) {
    tile.flags[tile.index(0, j)] |= kernels::dirichlet;
    tile.flags[tile.index(w - 1, j)] |= kernels::dirichlet;
    tile.values[tile.index(w - 1, j)] = 1;
  }
  for (int j = 0; j + 1 < h; j += gap)
    for (int i = 16; i < w - 16; ++i) tile.flags[tile.index(i, j)] |= kernels::wall_north;
  return tile;
}

TEST(CoarsestLevel, WideCoarsestLevelsGiveCholmodsSolutionForAnyThreadCount) {
  for (auto [gap, levels] : {std::pair{2, 1}, std::pair{3, 2}}) {
    const TexelTile tile = comb(gap);
    EXPECT_EQ(LaplaceMultigrid(tile).level_count(), levels) << "gap " << gap;
    expect_cholmods_solution_on_any_thread_count(tile, "comb gap " + std::to_string(gap));
  }
}

TEST(CoarsestLevel, ConcurrentSolvesOfAWideCoarsestLevelGiveTheSoloBits) {
  // The CHOLMOD factor of a wide coarsest level is simplicial in a given order (no BLAS, no
  // METIS), so it runs without the process-wide CHOLMOD lock: four threads solving at once
  // must each get exactly the solo solution.
  const TexelTile tile = comb(3);
  LaplaceMultigridOptions options;
  options.tolerance = 1e-11;
  options.execution = kernels::Execution::serial;  // one thread per solve
  TexelTile solo = tile;
  solve_laplace_multigrid(solo, options);
  std::vector<int> mismatches(4, 0);  // per thread: solves that differ from the solo one
  std::vector<std::thread> threads;
  for (std::size_t k = 0; k < mismatches.size(); ++k)
    threads.emplace_back([&, k] {
      for (int repeat = 0; repeat < 3; ++repeat) {
        TexelTile solved = tile;
        solve_laplace_multigrid(solved, options);
        mismatches[k] += solved.values != solo.values;
      }
    });
  for (std::thread& t : threads) t.join();
  for (int m : mismatches) EXPECT_EQ(m, 0);
}

}  // namespace
}  // namespace dgtex
