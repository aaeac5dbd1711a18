// The algebraic multigrid CG for texel graphs that no planar patch holds
// (runtime/graph_laplacian_amg.h): it reaches its tolerance on graph Laplacians with walls
// and Dirichlet data in few iterations, agrees with a sparse Cholesky solve, keeps its
// iteration count as the graph grows, solves a graph on which aggregation stalls (the
// coarsest level factored sparse), starts from the caller's guess, and reports failure
// instead of returning an unconverged answer (and refuses a matrix it cannot read).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include <Eigen/SparseCholesky>

#include "graph_laplacian_amg.h"  // internal (runtime/)

namespace dgtex {
namespace {

using detail::SparseRows;

struct System {
  SparseRows a;
  Eigen::VectorXd b;
};

// The 5-point texel Laplacian of an n x n grid, as solve_mesh_texel_laplace builds it:
// degree on the diagonal, -1 per coupling, couplings to Dirichlet texels (the left column at
// +1, the right at -1, outside the grid) moved to b. A wall cuts the couplings across the
// middle row over the left 3/4 of the grid (a slit, as a cut makes), and a second one runs
// up from the bottom at x = n / 3.
System slit_grid(int n) {
  auto id = [n](int i, int j) { return j * n + i; };
  auto walled = [n](int i, int j, int i2, int j2) {
    const bool across_slit = std::min(j, j2) == n / 2 - 1 && std::max(j, j2) == n / 2 && i < 3 * n / 4;
    const bool across_post = std::min(i, i2) == n / 3 - 1 && std::max(i, i2) == n / 3 && j < n / 4;
    return across_slit || across_post;
  };
  System s{SparseRows(n * n, n * n), Eigen::VectorXd::Zero(n * n)};
  s.a.reserve(Eigen::VectorXi::Constant(n * n, 5));
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int v = id(i, j);
      std::vector<int> columns = {v};
      int degree = 0;
      for (auto [i2, j2] : {std::pair{i - 1, j}, std::pair{i + 1, j}, std::pair{i, j - 1}, std::pair{i, j + 1}}) {
        if (j2 < 0 || j2 >= n || walled(i, j, i2, j2)) continue;
        ++degree;
        if (i2 < 0) s.b[v] += 1.0;
        else if (i2 >= n) s.b[v] -= 1.0;
        else columns.push_back(id(i2, j2));
      }
      std::sort(columns.begin(), columns.end());
      for (int c : columns) s.a.insert(v, c) = c == v ? degree : -1.0;
    }
  s.a.makeCompressed();
  return s;
}

Eigen::VectorXd cholesky_solution(const System& s) {
  const Eigen::SparseMatrix<double> a = s.a;
  Eigen::SimplicialLLT<Eigen::SparseMatrix<double>> llt(a);
  EXPECT_EQ(llt.info(), Eigen::Success);
  return llt.solve(s.b);
}

double relative_residual(const System& s, const Eigen::VectorXd& x) { return (s.b - s.a * x).norm() / s.b.norm(); }

TEST(GraphLaplacianAmg, SolvesASlitGridToCholeskysAnswerInFewIterations) {
  const System s = slit_grid(120);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(s.b.size());
  const detail::GraphAmgStats stats = detail::solve_graph_laplacian_amg(s.a, s.b, x, 1e-10, 100);
  EXPECT_GE(stats.levels, 3);  // 14,400 unknowns coarsen to a dense level of at most 400
  EXPECT_LE(stats.iterations, 20);
  EXPECT_LE(stats.relative_residual, 1e-10);
  EXPECT_LE(relative_residual(s, x), 1e-9);  // the true residual, not only the recursive one
  const Eigen::VectorXd reference = cholesky_solution(s);
  EXPECT_LT((x - reference).cwiseAbs().maxCoeff(), 1e-7);
  // Not vacuous: the field spans most of the data's range, and the slit shows as a jump
  // between texels on either side of it (0.022 at x = 30; the field's slope along y away
  // from the walls is far smaller).
  EXPECT_GT(x.maxCoeff() - x.minCoeff(), 1.5);
  EXPECT_GT(std::abs(x[59 * 120 + 30] - x[60 * 120 + 30]), 0.01);
  EXPECT_LT(std::abs(x[59 * 120 + 110] - x[60 * 120 + 110]), 0.01);  // past the slit's end
}

TEST(GraphLaplacianAmg, IterationsDoNotGrowWithTheGrid) {
  int small = 0, large = 0;
  for (auto [n, iterations] : {std::pair{40, &small}, std::pair{160, &large}}) {
    const System s = slit_grid(n);
    Eigen::VectorXd x = Eigen::VectorXd::Zero(s.b.size());
    *iterations = detail::solve_graph_laplacian_amg(s.a, s.b, x, 1e-8, 100).iterations;
  }
  // 16x the unknowns: a multigrid's count stays about the same (CG alone would need ~4x).
  EXPECT_LE(large, small + 4) << small << " -> " << large;
}

TEST(GraphLaplacianAmg, StartsFromTheCallersGuess) {
  const System s = slit_grid(60);
  Eigen::VectorXd x = cholesky_solution(s);
  const Eigen::VectorXd solution = x;
  const detail::GraphAmgStats stats = detail::solve_graph_laplacian_amg(s.a, s.b, x, 1e-6, 100);
  EXPECT_EQ(stats.iterations, 0);  // the guess already meets the tolerance: no hierarchy built
  EXPECT_EQ(stats.levels, 0);
  EXPECT_EQ(x, solution);
}

TEST(GraphLaplacianAmg, ReportsAToleranceItCannotReach) {
  const System s = slit_grid(60);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(s.b.size());
  EXPECT_THROW(detail::solve_graph_laplacian_amg(s.a, s.b, x, 1e-14, 2), std::runtime_error);
}

TEST(GraphLaplacianAmg, RefusesAnUncompressedMatrix) {
  System s = slit_grid(30);
  s.a.uncompress();
  Eigen::VectorXd x = Eigen::VectorXd::Zero(s.b.size());
  EXPECT_THROW(detail::solve_graph_laplacian_amg(s.a, s.b, x, 1e-6, 100), std::invalid_argument);
}

TEST(GraphLaplacianAmg, ZeroRightSideGivesZero) {
  System s = slit_grid(30);
  s.b.setZero();
  Eigen::VectorXd x = Eigen::VectorXd::Constant(s.b.size(), 0.5);
  detail::solve_graph_laplacian_amg(s.a, s.b, x, 1e-6, 100);
  EXPECT_EQ(x, Eigen::VectorXd::Zero(s.b.size()));
}

// Couplings below the strength threshold leave every node its own aggregate: coarsening
// stalls at once and the whole 900-node system is the coarsest level, factored sparse.
TEST(GraphLaplacianAmg, StalledCoarseningFactorsTheCoarsestLevelSparse) {
  const int n = 900;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> weight(0.01, 0.05);
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::VectorXd diagonal = Eigen::VectorXd::Constant(n, 1.0);
  for (int i = 0; i + 1 < n; ++i) {
    const double w = weight(rng);
    entries.emplace_back(i, i + 1, -w);
    entries.emplace_back(i + 1, i, -w);
    diagonal[i] += w, diagonal[i + 1] += w;
  }
  for (int i = 0; i < n; ++i) entries.emplace_back(i, i, diagonal[i]);
  System s{SparseRows(n, n), Eigen::VectorXd::LinSpaced(n, -1.0, 1.0)};
  s.a.setFromTriplets(entries.begin(), entries.end());
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  const detail::GraphAmgStats stats = detail::solve_graph_laplacian_amg(s.a, s.b, x, 1e-12, 100);
  EXPECT_EQ(stats.levels, 1);
  EXPECT_LE(stats.iterations, 2);  // the "cycle" is the exact solve
  EXPECT_LE(relative_residual(s, x), 1e-12);
}

}  // namespace
}  // namespace dgtex
