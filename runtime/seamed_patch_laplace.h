#pragma once
// Internal (used by solve_mesh_texel_laplace): the texel Laplace problem of a patch tile
// plus "seam" couplings between texels that are not grid neighbours there, as when a ring of
// elements (around a cylinder) is cut open into a chain to lie in a plane. Conjugate
// gradients on the closed operator A = A_chain + S (S: the seams' rank-one terms),
// preconditioned by the open chain's V-cycle between two exact solves on the seam strip
// (the unknowns within 3 texels of a seam texel; banded Cholesky), symmetric
// multiplicative Schwarz. The V-cycle alone leaves up to one outlier per seam coupling (34
// iterations on slinky's step-17 ring from 0); with the strip solves 14. Replaces CHOLMOD
// for such regions (slinky: 4 x 128^2 texels, see README "Several elements on one patch
// tile"). A poor initial guess (relative residual > 0.1: a new function, x = 0) is first
// replaced by the open chain's solution (the hierarchy's own multigrid solve): 7 iterations
// from there on that ring.
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
// to options.tolerance, relative residual of the closed operator. A part of the ring whose
// only Dirichlet data lie across a seam is solved too (the chain then pins its seam texels
// for the preconditioner). Throws std::runtime_error (the caller falls back to a direct
// solve) if a free texel has no data even on the ring or CG does not converge in
// options.max_cycles iterations; std::invalid_argument for bad seams.
LaplaceSolveStats solve_seamed_patch_laplace(kernels::TexelTile& tile, const std::vector<SeamCoupling>& seams,
                                             const LaplaceMultigridOptions& options = {});

}  // namespace dgtex::detail
