#pragma once
// One entry point for the harmonic enrichment's Laplace solves: the multigrid (default,
// warm-started from tile.values) or CHOLMOD (the reference).
// A pure function over a caller-owned tile (thread-safe on distinct tiles; uses all OpenMP
// threads). Values dimensionless.
#include <string>

#include "dgtex/kernels/texel_grid.h"
#include "dgtex/laplace_multigrid.h"
#include "dgtex/laplace_problem.h"

namespace dgtex {

enum class LaplaceSolver { multigrid, cholmod };

// "multigrid" or "cholmod"; throws std::invalid_argument otherwise.
LaplaceSolver parse_laplace_solver(const std::string& name);
std::string laplace_solver_name(LaplaceSolver solver);

// Solves the harmonic problem on `tile` in place (see laplace_direct.h / laplace_multigrid.h).
// With the multigrid, the free texels' current values are the initial guess (warm start
// while a cut advances) unless options.warm_start is false.
LaplaceSolveStats solve_laplace(kernels::TexelTile& tile, LaplaceSolver solver = LaplaceSolver::multigrid,
                                const LaplaceMultigridOptions& options = {});

}  // namespace dgtex
