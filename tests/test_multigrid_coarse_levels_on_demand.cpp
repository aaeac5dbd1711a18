// Coarse levels built on demand (LaplaceMultigrid::CoarseLevels::on_demand, used by
// solve_laplace_multigrid and the seamed patch solve): a warm start that already meets the
// tolerance returns its values unchanged without building them; every other solve, and the
// preconditioner, gives the bits of a hierarchy built whole at construction.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "dgtex/laplace_domains.h"
#include "dgtex/laplace_multigrid.h"
#include "seamed_patch_laplace.h"  // internal (runtime/)

namespace dgtex {
namespace {

using kernels::TexelTile;
using CoarseLevels = LaplaceMultigrid::CoarseLevels;

bool same_bits(const std::vector<double>& a, const std::vector<double>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
}

// The spiral domain, solved to the default tolerance.
TexelTile solved_spiral() {
  TexelTile tile = make_laplace_domain(LaplaceDomain::spiral, 128);
  solve_laplace_multigrid(tile);
  return tile;
}

TEST(MultigridCoarseLevelsOnDemand, ConvergedWarmStartBuildsNoCoarseLevelAndKeepsItsValues) {
  TexelTile tile = solved_spiral();
  const std::vector<double> before = tile.values;
  LaplaceMultigrid multigrid(tile, {}, CoarseLevels::on_demand);
  EXPECT_EQ(multigrid.level_count(), 1);
  const LaplaceSolveStats stats = multigrid.solve(tile);
  EXPECT_EQ(stats.iterations, 0);
  EXPECT_LE(stats.relative_residual, LaplaceMultigridOptions{}.tolerance);
  EXPECT_EQ(multigrid.level_count(), 1) << "no coarse level was needed";
  EXPECT_TRUE(same_bits(tile.values, before));
  // The one-call solve takes the same shortcut.
  const LaplaceSolveStats again = solve_laplace_multigrid(tile);
  EXPECT_EQ(again.iterations, 0);
  EXPECT_TRUE(same_bits(tile.values, before));
}

TEST(MultigridCoarseLevelsOnDemand, SolvesThatIterateGiveTheBitsOfAWholeHierarchy) {
  // A new wall: the old field becomes a warm start that needs a few iterations.
  TexelTile changed = solved_spiral();
  add_vertical_wall(changed, 100, 10, 40);
  for (const bool warm : {true, false}) {
    LaplaceMultigridOptions options;
    options.warm_start = warm;
    TexelTile whole_tile = changed, lazy_tile = changed;
    LaplaceMultigrid whole(whole_tile, options), lazy(lazy_tile, options, CoarseLevels::on_demand);
    EXPECT_EQ(lazy.level_count(), 1);
    const LaplaceSolveStats a = whole.solve(whole_tile), b = lazy.solve(lazy_tile);
    EXPECT_GT(b.iterations, 0);
    EXPECT_EQ(a.iterations, b.iterations);
    EXPECT_EQ(lazy.level_count(), whole.level_count());
    EXPECT_TRUE(same_bits(whole_tile.values, lazy_tile.values)) << "warm start " << warm;
    // A second solve reuses the levels the first one built.
    const int levels = lazy.level_count();
    lazy.solve(lazy_tile);
    EXPECT_EQ(lazy.level_count(), levels);
  }
}

TEST(MultigridCoarseLevelsOnDemand, PreconditionerBuildsThemAndMatchesAWholeHierarchy) {
  const TexelTile tile = make_laplace_domain(LaplaceDomain::slit, 64);
  LaplaceMultigrid whole(tile), lazy(tile, {}, CoarseLevels::on_demand);
  std::vector<double> r(tile.values.size()), z_whole, z_lazy;
  for (std::size_t t = 0; t < r.size(); ++t) r[t] = std::sin(0.37 * static_cast<double>(t));
  whole.precondition(r, z_whole);
  lazy.precondition(r, z_lazy);
  EXPECT_EQ(lazy.level_count(), whole.level_count());
  EXPECT_GT(lazy.level_count(), 1);
  EXPECT_TRUE(same_bits(z_whole, z_lazy));
}

// A ring (a strip whose ends couple through seams) solved, then solved again from its own
// solution: no iteration, the values unchanged.
TEST(MultigridCoarseLevelsOnDemand, SeamedPatchFromItsOwnSolutionReturnsAtOnce) {
  const int w = 48, h = 24;
  TexelTile tile(w, h);
  for (int i = 0; i < w; ++i) {
    tile.flags[tile.index(i, 0)] |= kernels::dirichlet;
    tile.flags[tile.index(i, h - 1)] |= kernels::dirichlet;
    tile.values[tile.index(i, h - 1)] = std::cos(0.3 * i);
  }
  std::vector<detail::SeamCoupling> seams;
  for (int j = 1; j + 1 < h; ++j) seams.push_back({tile.index(w - 1, j), tile.index(0, j)});
  const LaplaceSolveStats first = detail::solve_seamed_patch_laplace(tile, seams);
  EXPECT_GT(first.iterations, 0);
  const std::vector<double> solved = tile.values;
  const LaplaceSolveStats second = detail::solve_seamed_patch_laplace(tile, seams);
  EXPECT_EQ(second.iterations, 0);
  EXPECT_LE(second.relative_residual, LaplaceMultigridOptions{}.tolerance);
  EXPECT_TRUE(same_bits(tile.values, solved));
}

}  // namespace
}  // namespace dgtex
