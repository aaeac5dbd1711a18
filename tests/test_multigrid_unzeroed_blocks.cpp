// The Laplace multigrid takes most of its arrays from the block cache without zero-filling
// them (runtime/multigrid_buffer.h, frame_zeroed_buffer): the setup and the solve must write
// every such entry before reading it. With poisoning on, those blocks are full of NaN; the
// solutions must then be bitwise those of hierarchies built from zeroed blocks.
#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <vector>

#include "dgtex/laplace_domains.h"
#include "dgtex/laplace_multigrid.h"
#include "multigrid_buffer.h"
#include "thread_count_support.h"

namespace dgtex {
namespace {

std::vector<double> solve_twice(const kernels::TexelTile& problem, const LaplaceMultigridOptions& options) {
  kernels::TexelTile tile = problem;
  LaplaceMultigrid multigrid(tile, options);
  multigrid.solve(tile);
  // A second solve on the same hierarchy (warm start from the first solution).
  for (std::size_t k = 0; k < tile.values.size(); ++k)
    if (!(tile.flags[k] & kernels::dirichlet)) tile.values[k] *= 0.5;
  multigrid.solve(tile);
  return tile.values;
}

TEST(MultigridFrameZeroedBuffer, GhostFrameIsZeroAndPoisonReachesTheInterior) {
  const std::size_t nx = 130, ny = 97;  // 100 KB: a cached block
  { detail::MultigridBuffer garbage(nx * ny, -3.0); }  // leaves a dirty block in the cache
  const detail::PoisonUnzeroedBlocksScope poison;
  const detail::MultigridBuffer v = detail::frame_zeroed_buffer(nx, ny);
  ASSERT_EQ(v.size(), nx * ny);
  int nan_interior = 0;
  for (std::size_t j = 0; j < ny; ++j)
    for (std::size_t i = 0; i < nx; ++i) {
      const bool ghost = i == 0 || j == 0 || i + 1 == nx || j + 1 == ny;
      if (ghost) EXPECT_EQ(v[j * nx + i], 0.0) << i << ", " << j;
      else nan_interior += std::isnan(v[j * nx + i]);
    }
  EXPECT_EQ(nan_interior, static_cast<int>((nx - 2) * (ny - 2)));  // the test hook works
}

class MultigridUnzeroedBlocks : public ::testing::TestWithParam<LaplaceDomain> {};

TEST_P(MultigridUnzeroedBlocks, PoisonedBlocksGiveTheSameSolution) {
  // T = 256: level-0 and level-1 arrays are large enough (>= 64 KiB) to come from the cache.
  const kernels::TexelTile problem = make_laplace_domain(GetParam(), 256);
  for (int threads : {1, 2}) {
    const test::ThreadCountGuard set_threads(threads);
    for (double coarse_tolerance : {0.0, 0.02}) {
      LaplaceMultigridOptions options;
      options.coarse_solve_tolerance = coarse_tolerance;
      const std::vector<double> zeroed = solve_twice(problem, options);
      std::vector<double> poisoned;
      {
        const detail::PoisonUnzeroedBlocksScope poison;
        poisoned = solve_twice(problem, options);
      }
      for (double v : poisoned) ASSERT_TRUE(std::isfinite(v));
      EXPECT_EQ(poisoned, zeroed) << "threads " << threads << ", coarse_solve_tolerance " << coarse_tolerance;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Domains, MultigridUnzeroedBlocks,
                         ::testing::Values(LaplaceDomain::open, LaplaceDomain::slit, LaplaceDomain::spiral,
                                           LaplaceDomain::chad),
                         [](const ::testing::TestParamInfo<LaplaceDomain>& info) { return laplace_domain_name(info.param); });

}  // namespace
}  // namespace dgtex
