#pragma once
// Multigrid smoothers: multi-colour Gauss-Seidel. Nodes of one colour are never coupled,
// so a colour sweep is a set of independent updates: the parallel form gives the same
// bits as the serial one for any thread count, and the sweep is a texture-filter pass
// (GPU-friendly, thesis §5.7). Red-black on the 5-point texel level (smoothing factor
// 1/4 vs 0.6 for damped Jacobi at the same memory traffic per sweep), four colours
// ((i mod 2, j mod 2)) on the 9-point coarse levels. A symmetric cycle runs the colours in
// reverse order after the coarse correction.
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

}  // namespace dgtex::kernels
