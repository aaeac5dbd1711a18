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
// Interpolation from a 9-point level is built from its lumped 5-point form (each diagonal
// coupling shared between the axis neighbours next to it that the node couples to; walls
// stay exact zeros), then the 5-point black-box rules above; the Galerkin product uses the
// full 9-point operator. Why: collapsing the full 9-point stencil gives lopsided weights at
// wall corners (e.g. 0.82/0.18 along a straight channel side, positive coarse couplings up to
// 1.14 x the diagonal on spiral level 2), and the energy lost at each corner adds up along
// the spiral's channel: two-grid PCG from level 1 needed 13 iterations on the spiral and 11
// on chad (T = 256; from level 0: 6). With the lumped form: 6 and 6. V(1,1)-CG, full
// hierarchy, T = 256/512/1024: spiral 16/17/18 -> 6/6/6 iterations, chad 13/16/22 -> 7/7/7,
// open/slit/accordion/one_ring unchanged (6); `dgtex bench laplace`, 1 thread, setup +
// solve: spiral T = 256/512/1024 18-24 -> 9, 78 -> 36-39, 420 -> 178 ms, chad 13-14 -> 9,
// 71-75 -> 36-38, 501 -> 190 ms; cost per iteration and setup unchanged within noise. Tried and rejected (same harness):
// de Zeeuw's (MGD9V) weights (spiral 17, chad 15-20), extra Gauss-Seidel sweeps on the nodes
// within 1-3 nodes of a wall on levels >= 1 (1-4 sweeps: spiral 17 -> 15-16), sharing the
// edge node's couplings by the cell centre's raw diagonal couplings (Ruge-Stueben style, the
// earlier rule) on top of the lumped form (no gain). Remaining: chad T = 256 0.111 per
// cycle (7 iterations), the 0.1 elsewhere.
//
// Both setup kernels (and their references, below) write the coarse arrays (padded layout, ghosts must be zero on entry
// and stay zero) for every coarse node and are gathers, so serial and parallel agree bitwise.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// Values and coefficients are dimensionless (texel units).
#include <cstdint>

#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/multigrid_grid.h"

namespace dgtex::kernels {

template <class Real>
struct InterpolationArraysOf {
  Real* xw; Real* xe; Real* ys; Real* yn; Real* sw; Real* se; Real* nw; Real* ne;
  InterpolationViewOf<Real> view() const { return {xw, xe, ys, yn, sw, se, nw, ne}; }
};
template <class Real>
struct Stencil9ArraysOf {
  Real* c; Real* e; Real* n; Real* ne; Real* nw;
  Stencil9ViewOf<Real> view() const { return {c, e, n, ne, nw}; }
};
using InterpolationArrays = InterpolationArraysOf<double>;
using Stencil9Arrays = Stencil9ArraysOf<double>;
using InterpolationArraysFloat = InterpolationArraysOf<float>;
using Stencil9ArraysFloat = Stencil9ArraysOf<float>;

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

// Single-precision hierarchy (the float preconditioner cycle): the same kernels reading and
// writing float arrays, every value formed in double and rounded when stored. So the float
// Galerkin operator is the double product of the float interpolation, rounded; the edge
// weights are the double ones rounded, the cell-centre weights are formed from those.
void build_interpolation_texels(GridShape fine, const std::uint8_t* bits, InterpolationArraysFloat p,
                                Execution execution = Execution::parallel);
void build_interpolation_stencil9(GridShape fine, Stencil9ViewFloat a, InterpolationArraysFloat p,
                                  Execution execution = Execution::parallel);
void galerkin_texels(GridShape fine, const std::uint8_t* bits, InterpolationViewFloat p, Stencil9ArraysFloat coarse_a,
                     Execution execution = Execution::parallel);
void galerkin_stencil9(GridShape fine, Stencil9ViewFloat a, InterpolationViewFloat p, Stencil9ArraysFloat coarse_a,
                       Execution execution = Execution::parallel);

// Both of the above for one coarse level (what the multigrid setup calls): the same results,
// with the uniform regions of the fine level found once.
void coarsen_texels(GridShape fine, const std::uint8_t* bits, InterpolationArrays p, Stencil9Arrays coarse_a,
                    Execution execution = Execution::parallel);
void coarsen_stencil9(GridShape fine, Stencil9View a, InterpolationArrays p, Stencil9Arrays coarse_a,
                      Execution execution = Execution::parallel);
void coarsen_texels(GridShape fine, const std::uint8_t* bits, InterpolationArraysFloat p, Stencil9ArraysFloat coarse_a,
                    Execution execution = Execution::parallel);
void coarsen_stencil9(GridShape fine, Stencil9ViewFloat a, InterpolationArraysFloat p, Stencil9ArraysFloat coarse_a,
                      Execution execution = Execution::parallel);

// Serial references: the general formulas at every coarse node. The kernels above copy the
// results of one small uniform grid into the uniform regions of a level (most of it away
// from walls; multigrid_galerkin.cpp) and agree with these bitwise (tested).
void build_interpolation_texels_reference(GridShape fine, const std::uint8_t* bits, InterpolationArrays p);
void build_interpolation_stencil9_reference(GridShape fine, Stencil9View a, InterpolationArrays p);
void galerkin_texels_reference(GridShape fine, const std::uint8_t* bits, InterpolationView p, Stencil9Arrays coarse_a);
void galerkin_stencil9_reference(GridShape fine, Stencil9View a, InterpolationView p, Stencil9Arrays coarse_a);
void build_interpolation_texels_reference(GridShape fine, const std::uint8_t* bits, InterpolationArraysFloat p);
void build_interpolation_stencil9_reference(GridShape fine, Stencil9ViewFloat a, InterpolationArraysFloat p);
void galerkin_texels_reference(GridShape fine, const std::uint8_t* bits, InterpolationViewFloat p,
                               Stencil9ArraysFloat coarse_a);
void galerkin_stencil9_reference(GridShape fine, Stencil9ViewFloat a, InterpolationViewFloat p,
                                 Stencil9ArraysFloat coarse_a);

}  // namespace dgtex::kernels
