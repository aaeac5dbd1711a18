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
// Edge nodes (fine nodes on a coarse grid line) do not collapse their couplings to the two
// cell-centre neighbours blindly: each such coupling is shared between the edge node's
// two coarse neighbours in proportion to the cell centre's own couplings to them (as in
// Ruge-Stueben interpolation), and collapsed only where the cell centre couples to
// neither (always the case on the 5-point level, where this is plain black-box). Why:
// at a gap in a wall (chad's 2-texel bridge) plain collapse puts the edge node half-way
// between inside and outside although its other neighbours are inside; measured energy
// of the disk's indicator on level 2 of chad T=128: 5.09 plain, 2.73 with this rule
// (level 0: 2.0), per-cycle reduction of V(1,1)-CG at T=256: chad 0.367 -> 0.327, spiral
// 0.436 -> 0.416, open/slit/accordion unchanged (0.085-0.094).
// Known limit (measured, T=256, CG): with level 1 solved exactly the reduction is <= 0.082
// on chad and spiral, with three levels 0.24-0.28, with the full hierarchy 0.33-0.42: the
// coarse spaces from level 2 on cannot represent modes that live on sub-coarse-grid
// features (a bridge or channel narrower than the coarse spacing). Tried and rejected:
// Jacobi iteration of the edge/cell-centre weights within the compact pattern (chad 0.25,
// spiral 0.32, but open/slit degrade from 0.085 to 0.11-0.18 through the boundary rows),
// more coarse smoothing (16 sweeps on level 1: 3-level rate 0.92 -> 0.88). What works: the
// robust cycle of LaplaceMultigridOptions::coarse_solve_tolerance (level 1 solved by inner CG).
// On the spiral the loss grows with the number of channel turns, not with sub-grid width
// (channels are 16 texels wide at T=256): V(1,1)-CG iterations at T=256 with the spiral cut
// after k arms (full hierarchy): k <= 4: 6, k = 8: 7, k = 12: 9, k = 16: 11, k = 21: 15, all
// arms: 16; with level 1 solved exactly always 6, with three levels (level 2 exact) 11. A
// 4x larger Dirichlet centre: 16, walls shifted by one texel: 16, channels 19 wide: 12; the
// accordion (a serpentine of 19 straight channels) stays at 6. So the level 1 -> 2
// interpolation loses energy at each corner of the spiral's channel, and the losses add up.
//
// Both setup kernels write the coarse arrays (padded layout, ghosts must be zero on entry
// and stay zero) for every coarse node and are gathers, so serial and parallel agree bitwise.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// Values and coefficients are dimensionless (texel units).
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
