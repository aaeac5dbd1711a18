// The seamed patch solve (runtime/seamed_patch_laplace.h): a strip whose two ends are
// coupled (a ring of elements cut open), solved by CG with the open strip's multigrid and
// exact solves on the seam strip as the preconditioner, against a direct solve of the
// closed operator.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <Eigen/SparseCholesky>

#include "dgtex/kernels/multigrid_unknowns.h"
#include "seamed_patch_laplace.h"
#include "thread_count_support.h"

namespace dgtex {
namespace {

constexpr double pi = 3.14159265358979323846;

// A w x h strip, periodic in x through seams (column w-1 to column 0): Dirichlet rows at the
// bottom (0) and top (sin of the angle, so the solution depends on the seam), and a cut (a
// wall) across the seam's middle rows.
struct Strip {
  kernels::TexelTile tile;
  std::vector<detail::SeamCoupling> seams;
  Strip(int w, int h) : tile(w, h) {
    for (int i = 0; i < w; ++i) {
      tile.flags[tile.index(i, 0)] |= kernels::dirichlet;
      tile.flags[tile.index(i, h - 1)] |= kernels::dirichlet;
      tile.values[tile.index(i, h - 1)] = std::sin(2 * pi * (i + 0.5) / w);
    }
    for (int j = h / 3; j < 2 * h / 3; ++j)
      for (int i : {w - 6, 2})  // walls on both sides of the seam
        tile.flags[tile.index(i, j)] |= kernels::wall_east;
    for (int j = 1; j + 1 < h; ++j) seams.push_back({tile.index(w - 1, j), tile.index(0, j)});
  }
};

// Direct solve of the closed operator on the free texels.
std::vector<double> direct(const Strip& s) {
  const kernels::TexelTile& tile = s.tile;
  const int n = tile.width * tile.height;
  std::vector<int> unknown(n, -1);
  int m = 0;
  for (int t = 0; t < n; ++t)
    if (!(tile.flags[t] & (kernels::dirichlet | kernels::inactive))) unknown[t] = m++;
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::VectorXd b = Eigen::VectorXd::Zero(m);
  auto couple = [&](int t, int o) {
    if (unknown[t] < 0) return;
    entries.emplace_back(unknown[t], unknown[t], 1.0);
    if (unknown[o] >= 0) entries.emplace_back(unknown[t], unknown[o], -1.0);
    else b[unknown[t]] += tile.values[o];
  };
  for (int j = 0; j < tile.height; ++j)
    for (int i = 0; i < tile.width; ++i) {
      const int t = tile.index(i, j);
      if (i + 1 < tile.width && kernels::texels_coupled_east(tile, i, j)) couple(t, t + 1), couple(t + 1, t);
      if (j + 1 < tile.height && kernels::texels_coupled_north(tile, i, j))
        couple(t, t + tile.width), couple(t + tile.width, t);
    }
  for (const auto& seam : s.seams) couple(seam.a, seam.b), couple(seam.b, seam.a);
  Eigen::SparseMatrix<double> a(m, m);
  a.setFromTriplets(entries.begin(), entries.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(a);
  const Eigen::VectorXd x = ldlt.solve(b);
  std::vector<double> values = tile.values;
  for (int t = 0; t < n; ++t)
    if (unknown[t] >= 0) values[t] = x[unknown[t]];
  return values;
}

// The seamed solve of the strip's tile (in place) to `tolerance`: its stats and the relative
// 2-norm difference from the direct solve of the closed operator.
struct Solved {
  LaplaceSolveStats stats;
  double difference = 0;
};
Solved solve_and_compare(Strip& strip, double tolerance) {
  const std::vector<double> reference = direct(strip);
  LaplaceMultigridOptions options;
  options.tolerance = tolerance;
  Solved solved;
  solved.stats = detail::solve_seamed_patch_laplace(strip.tile, strip.seams, options);
  double norm = 0;
  for (std::size_t t = 0; t < reference.size(); ++t)
    solved.difference += std::pow(strip.tile.values[t] - reference[t], 2), norm += std::pow(reference[t], 2);
  solved.difference = std::sqrt(solved.difference / norm);
  return solved;
}

TEST(SeamedPatchLaplace, RingMatchesTheDirectSolve) {
  Strip strip(256, 64);  // a ring of 4 elements of T = 64, cut open
  const auto [stats, difference] = solve_and_compare(strip, 1e-9);
  EXPECT_LE(stats.relative_residual, 1e-9);
  EXPECT_LT(difference, 1e-7);
  // The seams add one outlier per coupled row at most (62 here): with the open strip's
  // V-cycle alone CG took 31 iterations to 1e-9 (28 from the open strip's solution); the
  // exact solves on the seam strip around it bring that to 10 (the open strip's own
  // problem needs ~9).
  EXPECT_LE(stats.iterations, 14) << "CG iterations";
  std::printf("seamed ring 256 x 64: %d CG iterations, %.2f ms\n", stats.iterations, stats.ms);
  // A warm start from the solution converges at once.
  LaplaceMultigridOptions options;
  options.tolerance = 1e-9;
  const LaplaceSolveStats again = detail::solve_seamed_patch_laplace(strip.tile, strip.seams, options);
  EXPECT_LE(again.iterations, 1);
}

// The solve's parallel passes (products, row sums) add in a fixed order: the same bits as
// its serial form at every thread count (cut_manager.cpp runs it serially when it solves
// several regions at once, in parallel when it solves one).
TEST(SeamedPatchLaplace, ParallelSolveIsTheSerialOneAtEveryThreadCount) {
  auto solve = [](kernels::Execution execution) {
    Strip strip(256, 64);
    LaplaceMultigridOptions options;
    options.tolerance = 1e-9;
    options.execution = execution;
    const LaplaceSolveStats stats = detail::solve_seamed_patch_laplace(strip.tile, strip.seams, options);
    EXPECT_GT(stats.iterations, 1);
    return strip.tile.values;
  };
  const std::vector<double> serial = solve(kernels::Execution::serial);
  for (int threads : {1, 2, 3, 4})
    EXPECT_EQ(test::with_threads(threads, [&] { return solve(kernels::Execution::parallel); }), serial) << threads;
}

// A ring pinned only by a short cut (+1 above, -1 below, as a new cut segment's data):
// nearly a Neumann problem, which the open strip preconditions poorly from x = 0. The
// solve starts from the open strip's own solution instead (its multigrid solve).
TEST(SeamedPatchLaplace, NearNeumannRingStartsFromTheOpenStripSolution) {
  Strip strip(256, 64);
  kernels::TexelTile& tile = strip.tile;
  for (int t = 0; t < 256 * 64; ++t) tile.flags[t] = 0, tile.values[t] = 0;
  for (int i = 100; i < 124; ++i) {
    tile.flags[tile.index(i, 31)] |= kernels::dirichlet | kernels::wall_north;
    tile.values[tile.index(i, 31)] = -1;
    tile.flags[tile.index(i, 32)] |= kernels::dirichlet;
    tile.values[tile.index(i, 32)] = 1;
  }
  strip.seams.clear();
  for (int j = 0; j < 64; ++j) strip.seams.push_back({tile.index(255, j), tile.index(0, j)});
  const auto [stats, difference] = solve_and_compare(strip, 1e-8);
  EXPECT_LT(difference, 1e-6);
  // Measured CG iterations: 25 from x = 0 with the V-cycle alone, 20 from the open strip's
  // solution, 13 with the seam-strip solves, 8 with both.
  EXPECT_LE(stats.iterations, 10) << "CG iterations";
  std::printf("near-Neumann ring 256 x 64: %d CG iterations, %.2f ms\n", stats.iterations, stats.ms);
}

// A ring standing upright in the patch: the seams join the top row to the bottom row, so
// the seam strip is a band of rows (ordered column by column for a narrow band).
TEST(SeamedPatchLaplace, RingAcrossRowsMatchesTheDirectSolve) {
  Strip strip(64, 256);
  kernels::TexelTile& tile = strip.tile;
  for (int t = 0; t < 64 * 256; ++t) tile.flags[t] = 0, tile.values[t] = 0;
  for (int j = 0; j < 256; ++j) {  // Dirichlet columns left (0) and right (a sine around)
    tile.flags[tile.index(0, j)] |= kernels::dirichlet;
    tile.flags[tile.index(63, j)] |= kernels::dirichlet;
    tile.values[tile.index(63, j)] = std::sin(2 * pi * (j + 0.5) / 256);
  }
  for (int i = 20; i < 40; ++i) tile.flags[tile.index(i, 250)] |= kernels::wall_north;  // a cut near the seam
  strip.seams.clear();
  for (int i = 1; i < 63; ++i) strip.seams.push_back({tile.index(i, 255), tile.index(i, 0)});
  const auto [stats, difference] = solve_and_compare(strip, 1e-9);
  EXPECT_LT(difference, 1e-7);
  EXPECT_LE(stats.iterations, 14) << "CG iterations";
  std::printf("seamed ring 64 x 256 (seams across rows): %d CG iterations\n", stats.iterations);
}

TEST(SeamedPatchLaplace, SolvesPartsWithDataOnlyAcrossASeamAndRejectsBadSeams) {
  // Left half: free texels walled off from the Dirichlet rows, reaching data only through
  // the seam. The open chain has no unknowns there, so its seam texels are pinned for the
  // preconditioner (this case went to CHOLMOD before).
  Strip strip(64, 16);
  for (int j = 1; j < 15; ++j) strip.tile.flags[strip.tile.index(31, j)] |= kernels::wall_east;
  for (int i = 0; i < 32; ++i) {
    strip.tile.flags[strip.tile.index(i, 0)] |= kernels::wall_north;
    strip.tile.flags[strip.tile.index(i, 14)] |= kernels::wall_north;
  }
  kernels::TexelTile island = strip.tile;
  const auto [stats, difference] = solve_and_compare(strip, 1e-10);
  EXPECT_LT(difference, 1e-8);
  const kernels::TexelTile& tile = strip.tile;
  EXPECT_GT(std::abs(tile.values[tile.index(10, 7)]), 1e-3);  // the left half got the ring's values
  EXPECT_LE(stats.iterations, 20);
  // A walled island has no data even on the ring.
  for (int j = 6; j < 9; ++j) {
    island.flags[island.index(44, j)] |= kernels::wall_east;
    island.flags[island.index(47, j)] |= kernels::wall_east;
  }
  for (int i = 45; i < 48; ++i) {
    island.flags[island.index(i, 5)] |= kernels::wall_north;
    island.flags[island.index(i, 8)] |= kernels::wall_north;
  }
  EXPECT_THROW(detail::solve_seamed_patch_laplace(island, strip.seams), std::runtime_error);
  EXPECT_THROW(detail::solve_seamed_patch_laplace(island, {{0, 64 * 16}}), std::invalid_argument);
  EXPECT_THROW(detail::solve_seamed_patch_laplace(island, {{0, 1}}), std::invalid_argument);  // both Dirichlet
}

}  // namespace
}  // namespace dgtex
