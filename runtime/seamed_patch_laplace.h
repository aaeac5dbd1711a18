#pragma once
// Internal (used by solve_mesh_texel_laplace): the texel Laplace problem of a patch tile
// plus "seam" couplings between texels that are not grid neighbours there, as when a ring of
// elements (around a cylinder) is cut open into a chain to lie in a plane. The tile
// multigrid of the open chain preconditions conjugate gradients on the closed operator:
// A = A_chain + S with S the seams' rank-one terms, so M^-1 A >= 1 with at most one outlier
// per seam coupling, and CG removes those in a few extra iterations. Replaces CHOLMOD for
// such regions (slinky: 4 x 128^2 texels, see README "Several elements on one patch tile").
// A poor initial guess (relative residual > 0.1: a new function, x = 0) is first replaced by
// the open chain's solution (the hierarchy's own multigrid solve): nearly-Neumann rings
// (a short new cut on a closed cylinder) took 34 CG iterations from 0, 6 cycles + 21 from it.
#include <vector>

#include "dgtex/kernels/texel_grid.h"
#include "dgtex/laplace_multigrid.h"
#include "dgtex/laplace_problem.h"

namespace dgtex::detail {

// Texels a and b (tile.index) coupled like grid neighbours (weight 1). Either may be a
// Dirichlet texel (then it is data), not both; neither inactive.
struct SeamCoupling {
  int a = 0, b = 0;
};

// Solves in place (tile.values of the free texels; the initial guess is their finite values)
// to options.tolerance, relative residual of the closed operator. Throws std::runtime_error
// (the caller falls back to a direct solve) if a free texel is not an unknown of the chain's
// hierarchy (a component whose only Dirichlet data lies across a seam) or CG does not
// converge in options.max_cycles iterations; std::invalid_argument for bad seams.
LaplaceSolveStats solve_seamed_patch_laplace(kernels::TexelTile& tile, const std::vector<SeamCoupling>& seams,
                                             const LaplaceMultigridOptions& options = {});

}  // namespace dgtex::detail
