// CHOLMOD reference solve of the harmonic texel problem: analytic solution, components
// without Dirichlet data, system symmetry, errors.
#include <gtest/gtest.h>

#include <stdexcept>

#include "dgtex/laplace_direct.h"
#include "dgtex/laplace_domains.h"
#include "dgtex/laplace_solver.h"

namespace dgtex {
namespace {

TEST(LaplaceDirect, OpenSquareIsLinear) {
  // +1 on column 0, -1 on column T-1, zero-Neumann top and bottom: u(i) = 1 - 2 i / (T - 1).
  const int T = 64;
  kernels::TexelTile tile = make_laplace_domain(LaplaceDomain::open, T);
  const LaplaceSolveStats stats = solve_laplace_direct(tile);
  EXPECT_LE(stats.relative_residual, 1e-12);
  for (int j = 0; j < T; ++j)
    for (int i = 0; i < T; ++i) EXPECT_NEAR(tile.values[tile.index(i, j)], 1.0 - 2.0 * i / (T - 1), 1e-11);
}

TEST(LaplaceDirect, ComponentWithoutDirichletDataIsZero) {
  kernels::TexelTile tile = make_laplace_domain(LaplaceDomain::open, 32);
  // Close a 6x6 island with Neumann walls and give it garbage values.
  add_vertical_wall(tile, 10, 10, 16);
  add_vertical_wall(tile, 16, 10, 16);
  add_horizontal_wall(tile, 10, 10, 16);
  add_horizontal_wall(tile, 16, 10, 16);
  for (int j = 10; j < 16; ++j)
    for (int i = 10; i < 16; ++i) tile.values[tile.index(i, j)] = 7.0;
  kernels::TexelTile reference = tile;
  solve_laplace(reference, LaplaceSolver::cholmod);
  for (LaplaceSolver solver : {LaplaceSolver::cholmod, LaplaceSolver::multigrid}) {
    kernels::TexelTile t = tile;
    solve_laplace(t, solver);
    for (int j = 10; j < 16; ++j)
      for (int i = 10; i < 16; ++i) EXPECT_EQ(t.values[t.index(i, j)], 0.0) << laplace_solver_name(solver);
    // Outside the island: a harmonic field between +1 and -1 (both solvers agree).
    EXPECT_NEAR(t.values[t.index(5, 5)], reference.values[reference.index(5, 5)], 1e-5);
    EXPECT_GT(t.values[t.index(5, 5)], 0.0);
    EXPECT_LT(t.values[t.index(5, 5)], 1.0);
  }
}

TEST(LaplaceDirect, AssembledSystemIsSymmetricWithDegreeDiagonal) {
  const kernels::TexelTile tile = make_laplace_domain(LaplaceDomain::chad, 48, TexelElementShape::tri);
  const TexelLaplaceSystem system = assemble_texel_laplace_system(tile);
  const Eigen::SparseMatrix<double> asym = system.A - Eigen::SparseMatrix<double>(system.A.transpose());
  EXPECT_EQ(asym.norm(), 0.0);
  // Row sums: degree minus unknown neighbours = number of Dirichlet neighbours >= 0.
  const Eigen::VectorXd row_sums = system.A * Eigen::VectorXd::Ones(system.A.cols());
  EXPECT_GE(row_sums.minCoeff(), 0.0);
  for (int k = 0; k < static_cast<int>(system.texel_of_unknown.size()); ++k)
    EXPECT_EQ(system.unknown_of_texel[system.texel_of_unknown[k]], k);
}

TEST(LaplaceDirect, MalformedTilesAreRejectedWithAMessage) {
  kernels::TexelTile empty;
  EXPECT_THROW(solve_laplace_direct(empty), std::invalid_argument);
  kernels::TexelTile short_values(8, 8);
  short_values.values.resize(10);
  try {
    solve_laplace_direct(short_values);
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("64"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_laplace_solver("amg"), std::invalid_argument);
  EXPECT_THROW(parse_laplace_domain("circle"), std::invalid_argument);
}

TEST(LaplaceDirect, NoDirichletDataGivesZero) {
  kernels::TexelTile tile(16, 16);
  for (double& v : tile.values) v = 3.0;
  for (LaplaceSolver solver : {LaplaceSolver::cholmod, LaplaceSolver::multigrid}) {
    kernels::TexelTile t = tile;
    solve_laplace(t, solver);
    for (double v : t.values) EXPECT_EQ(v, 0.0);
  }
}

}  // namespace
}  // namespace dgtex
