#pragma once
// Multigrid setup in the style of black-box multigrid (Dendy 1982): operator-dependent
// interpolation and Galerkin coarse operators A_c = P^T A P.
//
// Why this coarsening: walls (cuts) are zero couplings of the fine operator. The
// interpolation weight of a fine node towards a coarse node is its collapsed coupling in
// that direction, so it is exactly 0 across a wall, and every column of P stays on one
// side of it; P^T A P then has exactly zero couplings across the wall on every coarse
// level (a one-texel slit stays a wall), wherever the wall lies relative to the coarse
// grid. Rediscretising coarse levels from coarsened flags cannot do that for walls that
// run through a coarse cell (measured: the spiral/accordion stall at ~0.5-0.9 per cycle
// with piecewise-constant aggregation). Dirichlet texels are no unknowns: their
// couplings only add to the diagonal, so interpolation decays towards them.
//
// Both setup kernels write the coarse arrays (padded layout, ghosts must be zero on entry
// and stay zero) for every coarse node and are gathers, so serial and parallel agree bitwise.
#include <cstdint>

#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/multigrid_grid.h"

namespace dgtex::kernels {

struct InterpolationArrays {
  double* xw; double* xe; double* ys; double* yn; double* sw; double* se; double* nw; double* ne;
  InterpolationView view() const { return {xw, xe, ys, yn, sw, se, nw, ne}; }
};
struct Stencil9Arrays {
  double* c; double* e; double* n; double* ne; double* nw;
  Stencil9View view() const { return {c, e, n, ne, nw}; }
};

// Interpolation from `coarse` (= fine.coarser()) to level 0 (the texel operator `bits`).
void build_interpolation_texels(GridShape fine, const std::uint8_t* bits, InterpolationArrays p,
                                Execution execution = Execution::parallel);
// Interpolation from `coarse` to a 9-point level.
void build_interpolation_stencil9(GridShape fine, Stencil9View a, InterpolationArrays p,
                                  Execution execution = Execution::parallel);

// Galerkin operator P^T A P on fine.coarser() for A = level 0 / a 9-point level.
void galerkin_texels(GridShape fine, const std::uint8_t* bits, InterpolationView p, Stencil9Arrays coarse_a,
                     Execution execution = Execution::parallel);
void galerkin_stencil9(GridShape fine, Stencil9View a, InterpolationView p, Stencil9Arrays coarse_a,
                       Execution execution = Execution::parallel);

}  // namespace dgtex::kernels
