#pragma once
// Multigrid smoothers: multi-colour Gauss-Seidel. Nodes of one colour are never coupled,
// so a colour sweep is a set of independent updates: the parallel form gives the same
// bits as the serial one for any thread count, and the sweep is a texture-filter pass
// (GPU-friendly, thesis §5.7). Red-black on the 5-point texel level (smoothing factor
// 1/4 vs 0.6 for damped Jacobi at the same memory traffic per sweep), four colours
// ((i mod 2, j mod 2)) on the 9-point coarse levels. A symmetric cycle runs the colours in
// reverse order after the coarse correction.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// Values are dimensionless.
#include <cstdint>

#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/multigrid_grid.h"

namespace dgtex::kernels {

// Level 0: x(t) = (b(t) + sum of x over coupled unknown neighbours) / degree(t) for the
// unknowns t with (i + j) % 2 == color. bits: LaplaceTexelBits, padded layout.
void smooth_texels_color(GridShape shape, const std::uint8_t* bits, const double* b, double* x, int color,
                         Execution execution = Execution::parallel);
// Naive serial reference of smooth_texels_color (same arithmetic order).
void smooth_texels_color_reference(GridShape shape, const std::uint8_t* bits, const double* b, double* x, int color);

// Coarse levels: x(t) = (b(t) - sum_{n != t} A(t, n) x(n)) / A(t, t) for the nodes with
// A(t, t) > 0 and (i % 2) + 2 (j % 2) == color.
void smooth_stencil9_color(GridShape shape, Stencil9View a, const double* b, double* x, int color,
                           Execution execution = Execution::parallel);
void smooth_stencil9_color_reference(GridShape shape, Stencil9View a, const double* b, double* x, int color);
// Single precision (the float preconditioner cycle); arithmetic in float.
void smooth_stencil9_color_reference(GridShape shape, Stencil9ViewFloat a, const float* b, float* x, int color);

// Whole sweeps in one streaming pass over the rows (what the multigrid runs). The second
// colour(s) of row j - 1 are updated right after the first colour(s) of row j, so x, b and
// the operator stream through the cache once per sweep instead of once per colour; rows at
// the borders of the fixed 32-row blocks (the parallel work items) are finished in a second,
// short pass. Every node sees exactly the inputs of the colour-by-colour order, so these are
// bitwise equal to the colour kernels above run in order (forward: colours 0, 1 [, 2, 3];
// backward: the reverse) for any thread count.
// If row_dot is given, row_dot[j] = sum over row j of b * x after the sweep (four-lane order
// of multigrid_residual.h; the preconditioned CG's r . z for free).
void smooth_texels_sweep(GridShape shape, const std::uint8_t* bits, const double* b, double* x, bool forward,
                         Execution execution = Execution::parallel, double* row_dot = nullptr);
// A forward sweep from x = 0 (x need not be initialised): red unknowns get b / degree, black
// unknowns their Gauss-Seidel update, every other node 0.
void smooth_texels_sweep_from_zero(GridShape shape, const std::uint8_t* bits, const double* b, double* x,
                                   Execution execution = Execution::parallel);
void smooth_stencil9_sweep(GridShape shape, Stencil9View a, const double* b, double* x, bool forward,
                           Execution execution = Execution::parallel);
void smooth_stencil9_sweep(GridShape shape, Stencil9ViewFloat a, const float* b, float* x, bool forward,
                           Execution execution = Execution::parallel);

// Conjugate-gradient step fused with the first sweep of the next preconditioner application:
// x += alpha p, r -= alpha q (row_norm2[j] = sum over row j of r^2, four-lane order), then
// z = smooth_texels_sweep_from_zero with b = r. Bitwise equal to those two steps in turn;
// saves one pass over r. The reference runs them in turn.
void cg_update_and_smooth_texels_from_zero(GridShape shape, const std::uint8_t* bits, double alpha, const double* p,
                                           const double* q, double* x, double* r, double* z, double* row_norm2,
                                           Execution execution = Execution::parallel);
void cg_update_and_smooth_texels_from_zero_reference(GridShape shape, const std::uint8_t* bits, double alpha,
                                                     const double* p, const double* q, double* x, double* r, double* z,
                                                     double* row_norm2);

}  // namespace dgtex::kernels
