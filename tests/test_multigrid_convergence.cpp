// Convergence of the Laplace multigrid (default options: V(1,1)-preconditioned CG) on the
// named domains: residual reduction per cycle and agreement with CHOLMOD.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "dgtex/laplace_direct.h"
#include "dgtex/laplace_domains.h"
#include "dgtex/laplace_multigrid.h"
#include "dgtex/laplace_solver.h"

namespace dgtex {
namespace {

struct Case {
  LaplaceDomain domain;
  int T;
  TexelElementShape shape;
};

std::string case_name(const Case& c) {
  return laplace_domain_name(c.domain) + "_" + std::to_string(c.T) + (c.shape == TexelElementShape::tri ? "_tri" : "_quad");
}

double max_relative_difference(const kernels::TexelTile& a, const kernels::TexelTile& b) {
  double diff = 0, scale = 0;
  for (std::size_t t = 0; t < a.values.size(); ++t) {
    diff = std::max(diff, std::abs(a.values[t] - b.values[t]));
    scale = std::max(scale, std::abs(b.values[t]));
  }
  return diff / scale;
}

// Cold solve to 1e-6 with the given options (default: the default options): geometric mean of
// the residual reduction per cycle.
double mean_reduction_per_cycle(const kernels::TexelTile& problem, int* cycles,
                                LaplaceMultigridOptions options = LaplaceMultigridOptions()) {
  options.warm_start = false;
  kernels::TexelTile tile = problem;
  std::vector<LaplaceConvergencePoint> history;
  const LaplaceSolveStats stats = solve_laplace_multigrid(tile, options, &history);
  *cycles = stats.iterations;
  return std::pow(history.back().relative_residual / history.front().relative_residual, 1.0 / stats.iterations);
}

class MultigridAgreesWithCholmod : public ::testing::TestWithParam<Case> {};

TEST_P(MultigridAgreesWithCholmod, To1e8Relative) {
  const Case c = GetParam();
  const kernels::TexelTile problem = make_laplace_domain(c.domain, c.T, c.shape);
  kernels::TexelTile direct = problem, multigrid = problem;
  solve_laplace(direct, LaplaceSolver::cholmod);
  LaplaceMultigridOptions options;
  options.tolerance = 1e-11;
  options.warm_start = false;
  const LaplaceSolveStats stats = solve_laplace(multigrid, LaplaceSolver::multigrid, options);
  EXPECT_LE(stats.relative_residual, 1e-11);
  EXPECT_LE(max_relative_difference(multigrid, direct), 1e-8);
}

class MultigridReduction : public ::testing::TestWithParam<Case> {};

TEST_P(MultigridReduction, AtMostOneTenthPerCycle) {
  const Case c = GetParam();
  int cycles = 0;
  const double rho = mean_reduction_per_cycle(make_laplace_domain(c.domain, c.T, c.shape), &cycles);
  std::printf("%s: %d cycles to 1e-6, mean reduction per cycle %.3f\n", case_name(c).c_str(), cycles, rho);
  EXPECT_LE(rho, 0.1);
}

const auto all_cases = ::testing::Values(
    Case{LaplaceDomain::open, 128, TexelElementShape::quad}, Case{LaplaceDomain::slit, 128, TexelElementShape::quad},
    Case{LaplaceDomain::spiral, 128, TexelElementShape::quad},
    Case{LaplaceDomain::accordion, 128, TexelElementShape::quad},
    Case{LaplaceDomain::chad, 128, TexelElementShape::quad}, Case{LaplaceDomain::one_ring, 64, TexelElementShape::quad},
    Case{LaplaceDomain::open, 128, TexelElementShape::tri}, Case{LaplaceDomain::slit, 128, TexelElementShape::tri},
    Case{LaplaceDomain::spiral, 128, TexelElementShape::tri}, Case{LaplaceDomain::accordion, 128, TexelElementShape::tri},
    Case{LaplaceDomain::chad, 128, TexelElementShape::tri}, Case{LaplaceDomain::slit, 256, TexelElementShape::quad});
auto name = [](const ::testing::TestParamInfo<Case>& info) { return case_name(info.param); };

INSTANTIATE_TEST_SUITE_P(Domains, MultigridAgreesWithCholmod, all_cases, name);

// The target (<= 0.1 per cycle) on every domain with the default cycle. The spiral
// and chad met it only with the robust cycle below until the interpolation of 9-point levels
// was built from their lumped 5-point form (kernels/dgtex/kernels/multigrid_galerkin.h).
INSTANTIATE_TEST_SUITE_P(Domains, MultigridReduction, all_cases, name);

// The robust cycle solves level 1 by CG to 2% in every cycle: kept as an option, tested here.
class MultigridRobustCycle : public ::testing::TestWithParam<Case> {};

TEST_P(MultigridRobustCycle, AtMostOneTenthPerCycleAndAgreesWithCholmod) {
  const Case c = GetParam();
  const kernels::TexelTile problem = make_laplace_domain(c.domain, c.T, c.shape);
  LaplaceMultigridOptions options;
  options.coarse_solve_tolerance = 0.02;
  int cycles = 0;
  const double rho = mean_reduction_per_cycle(problem, &cycles, options);
  std::printf("%s (robust cycle): %d cycles to 1e-6, mean reduction per cycle %.3f\n", case_name(c).c_str(), cycles, rho);
  EXPECT_LE(rho, 0.1);
  kernels::TexelTile direct = problem, multigrid = problem;
  solve_laplace(direct, LaplaceSolver::cholmod);
  options.tolerance = 1e-11;
  options.warm_start = false;
  EXPECT_LE(solve_laplace(multigrid, LaplaceSolver::multigrid, options).relative_residual, 1e-11);
  EXPECT_LE(max_relative_difference(multigrid, direct), 1e-8);
}

INSTANTIATE_TEST_SUITE_P(Domains, MultigridRobustCycle, all_cases, name);

TEST(MultigridRobustness, RandomTilesAndCycleVariantsMatchCholmod) {
  // Small random tiles (single texels, single rows, isolated components, Dirichlet islands)
  // through every cycle path: CG or plain cycles, V or F, with and without pre- or
  // post-smoothing (the red-black shortcuts apply only with both).
  std::mt19937 rng(11);
  struct Variant { bool cg; MultigridCycle cycle; int pre, post; double coarse_solve_tolerance; };
  const Variant variants[] = {{true, MultigridCycle::v, 1, 1, 0.0},  {true, MultigridCycle::v, 2, 2, 0.0},
                              {false, MultigridCycle::v, 1, 1, 0.0}, {false, MultigridCycle::f, 2, 1, 0.0},
                              {false, MultigridCycle::v, 0, 2, 0.0}, {false, MultigridCycle::v, 2, 0, 0.0},
                              {true, MultigridCycle::v, 1, 1, 0.02}, {false, MultigridCycle::v, 1, 1, 0.1}};
  for (int k = 0; k < 60; ++k) {
    const int w = 1 + static_cast<int>(rng() % 48), h = 1 + static_cast<int>(rng() % 48);
    kernels::TexelTile problem(w, h);
    for (std::size_t t = 0; t < problem.flags.size(); ++t) {
      std::uint8_t f = 0;
      if (rng() % 6 == 0) f |= kernels::wall_east;
      if (rng() % 6 == 0) f |= kernels::wall_north;
      if (rng() % 25 == 0) f |= kernels::dirichlet;
      if (rng() % 30 == 0) f |= kernels::inactive;
      problem.flags[t] = f;
      problem.values[t] = (f & kernels::dirichlet) ? static_cast<double>(rng() % 200) / 100.0 - 1.0 : 0.0;
    }
    kernels::TexelTile direct = problem;
    solve_laplace(direct, LaplaceSolver::cholmod);
    for (const Variant& v : variants) {
      LaplaceMultigridOptions options;
      options.tolerance = 1e-12;
      options.max_cycles = 400;
      options.warm_start = false;
      options.use_as_cg_preconditioner = v.cg;
      options.cycle = v.cycle;
      options.pre_smoothing = v.pre;
      options.post_smoothing = v.post;
      options.coarse_solve_tolerance = v.coarse_solve_tolerance;
      options.coarsest_nodes = 4;  // deep hierarchies even on small tiles
      kernels::TexelTile multigrid = problem;
      solve_laplace(multigrid, LaplaceSolver::multigrid, options);
      double diff = 0, scale = 1e-300;
      for (std::size_t t = 0; t < direct.values.size(); ++t) {
        diff = std::max(diff, std::abs(multigrid.values[t] - direct.values[t]));
        scale = std::max(scale, std::abs(direct.values[t]));
      }
      EXPECT_LE(diff / scale, 1e-8) << "tile " << k << " (" << w << "x" << h << "), cg " << v.cg << ", pre " << v.pre
                                    << ", post " << v.post;
    }
  }
}

TEST(MultigridWarmStart, AdvancingCutNeedsFewerCycles) {
  // A cut advancing by 4 texels: the previous enrichment is a good initial guess.
  auto make = [](int length) {
    kernels::TexelTile tile(128, 128);
    add_vertical_wall(tile, 65, 0, length);
    for (int j = 0; j < length; ++j) {
      tile.flags[tile.index(64, j)] |= kernels::dirichlet;
      tile.values[tile.index(64, j)] = 1.0;
      tile.flags[tile.index(65, j)] |= kernels::dirichlet;
      tile.values[tile.index(65, j)] = -1.0;
    }
    return tile;
  };
  kernels::TexelTile before = make(60);
  solve_laplace(before);
  kernels::TexelTile cold = make(64), warm = make(64);
  for (std::size_t t = 0; t < warm.values.size(); ++t)
    if (!(warm.flags[t] & kernels::dirichlet)) warm.values[t] = before.values[t];
  LaplaceMultigridOptions cold_options;
  cold_options.warm_start = false;
  const LaplaceSolveStats cold_stats = solve_laplace(cold, LaplaceSolver::multigrid, cold_options);
  const LaplaceSolveStats warm_stats = solve_laplace(warm, LaplaceSolver::multigrid);
  std::printf("cold %d cycles, warm %d cycles\n", cold_stats.iterations, warm_stats.iterations);
  EXPECT_LT(warm_stats.iterations, cold_stats.iterations);
  EXPECT_LE(warm_stats.relative_residual, 1e-6);
}

}  // namespace
}  // namespace dgtex
