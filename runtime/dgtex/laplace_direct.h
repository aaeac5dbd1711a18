#pragma once
// Direct (CHOLMOD supernodal Cholesky) solve of the harmonic texel problem: the reference
// for the multigrid, and the assembly of the reduced SPD system for other sparse solvers.
// Pure functions: TexelLaplaceSystem owns its matrix and vectors (Eigen, by value);
// nothing is kept between calls (thread-safe on distinct tiles). Values are dimensionless.
#include <cstddef>
#include <vector>

#include <Eigen/SparseCore>

#include "dgtex/kernels/texel_grid.h"
#include "dgtex/laplace_problem.h"

namespace dgtex {

// Solves the harmonic problem on `tile` in place: values of free texels are overwritten
// (0 on components without Dirichlet data); Dirichlet and inactive texels keep theirs.
// Throws std::invalid_argument for a malformed tile, std::runtime_error if CHOLMOD fails.
LaplaceSolveStats solve_laplace_direct(kernels::TexelTile& tile);

// The reduced SPD system: one unknown per free texel of a component with Dirichlet data,
// numbered in texel order (j * width + i). A is n x n (lower and upper parts stored),
// b holds the coupled Dirichlet neighbours' values.
struct TexelLaplaceSystem {
  Eigen::SparseMatrix<double> A;
  Eigen::VectorXd b;
  std::vector<int> texel_of_unknown;   // n entries
  std::vector<int> unknown_of_texel;   // width * height entries, -1 if not an unknown
};
TexelLaplaceSystem assemble_texel_laplace_system(const kernels::TexelTile& tile);

// Writes a solution x of the reduced system into tile.values (free texels outside the
// system get 0).
void scatter_texel_laplace_solution(const TexelLaplaceSystem& system, const Eigen::VectorXd& x, kernels::TexelTile& tile);

}  // namespace dgtex
