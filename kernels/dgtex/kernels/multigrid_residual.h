#pragma once
// Multigrid residuals r = b - A x (0 at nodes without unknown). Each also writes the sum
// of r^2 of every grid row into row_norm2[j], so callers form ||r||^2 by adding the rows
// in order: a norm that does not depend on the thread count. Coarse levels sum a row left
// to right; level 0 (the texel kernels here and in multigrid_smooth.h) in four interleaved
// lanes, texel i into lane i mod 4, total (lane 0 + lane 1) + (lane 2 + lane 3), which
// lets it add four texels per vector instruction.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// Values are dimensionless.
#include <cstdint>

#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/multigrid_grid.h"

namespace dgtex::kernels {

// Level 0 (5-point texel operator, LaplaceTexelBits). row_norm2 may be null.
void residual_texels(GridShape shape, const std::uint8_t* bits, const double* b, const double* x, double* r,
                     double* row_norm2, Execution execution = Execution::parallel);
void residual_texels_reference(GridShape shape, const std::uint8_t* bits, const double* b, const double* x, double* r,
                               double* row_norm2);

// Residual at the level-0 nodes of one red-black colour ((i + j) % 2 == color) only; the
// other entries of r are not written. Right after a forward red-black sweep the black
// (colour 1) residual is zero in exact arithmetic, so the multigrid computes and restricts
// only the red half (restrict_red_residual).
void residual_texels_color(GridShape shape, const std::uint8_t* bits, const double* b, const double* x, double* r,
                           int color, Execution execution = Execution::parallel);
void residual_texels_color_reference(GridShape shape, const std::uint8_t* bits, const double* b, const double* x,
                                     double* r, int color);

// The two steps above that follow a forward red-black sweep on level 0, in one pass:
// b_coarse = P^T r for r = the red residual (residual_texels_color, colour 0; 0 at black
// nodes), as restrict_red_residual (multigrid_transfer.h) computes it, without storing r.
// Each coarse node forms the residual at its own node and at the two cell centres to its
// east; those to its west come from the previous node of the row, so every cell-centre
// residual is formed twice (once per coarse row) and r never makes a round trip through
// memory. Bitwise equal to residual_texels_color + restrict_red_residual (the reference).
// Measured (open T = 1024, CPU, 1 thread): the two kernels took 9.4% of a solve.
void restrict_red_residual_texels(GridShape fine, GridShape coarse, InterpolationView p, const std::uint8_t* bits,
                                  const double* b, const double* x, double* b_coarse,
                                  Execution execution = Execution::parallel);
void restrict_red_residual_texels_reference(GridShape fine, GridShape coarse, InterpolationView p,
                                            const std::uint8_t* bits, const double* b, const double* x,
                                            double* b_coarse);
// Single-precision coarse level (float interpolation and b_coarse; the sum is formed in
// double and rounded once).
void restrict_red_residual_texels(GridShape fine, GridShape coarse, InterpolationViewFloat p, const std::uint8_t* bits,
                                  const double* b, const double* x, float* b_coarse,
                                  Execution execution = Execution::parallel);
void restrict_red_residual_texels_reference(GridShape fine, GridShape coarse, InterpolationViewFloat p,
                                            const std::uint8_t* bits, const double* b, const double* x,
                                            float* b_coarse);

// Coarse levels (9-point). row_norm2 may be null.
void residual_stencil9(GridShape shape, Stencil9View a, const double* b, const double* x, double* r,
                       double* row_norm2, Execution execution = Execution::parallel);
void residual_stencil9_reference(GridShape shape, Stencil9View a, const double* b, const double* x, double* r,
                                 double* row_norm2);
// Single precision (arithmetic in float; row_norm2 accumulated in double).
void residual_stencil9(GridShape shape, Stencil9ViewFloat a, const float* b, const float* x, float* r,
                       double* row_norm2, Execution execution = Execution::parallel);
void residual_stencil9_reference(GridShape shape, Stencil9ViewFloat a, const float* b, const float* x, float* r,
                                 double* row_norm2);

// y = A x on level 0 (for conjugate gradients); row_dot[j] = sum over row j of x * y.
void apply_texels(GridShape shape, const std::uint8_t* bits, const double* x, double* y, double* row_dot,
                  Execution execution = Execution::parallel);

// y[t] = (A x)[t] for the listed level-0 texels t (padded indices) only, bitwise as
// apply_texels writes them (its reference); the other entries of y are not written. For a
// caller that needs A x where x changed on a few texels (seamed_patch_laplace's strip):
// serial, since such lists are short (~1-2k texels) next to a pass over the grid.
void apply_texels_at(GridShape shape, const std::uint8_t* bits, const double* x, const std::int64_t* texels,
                     std::int64_t count, double* y);

// Conjugate-gradient step on level 0 in one streaming pass: p = z + beta p, then q = A p
// and row_dot[j] = sum over row j of p * q (four-lane order, above). Bitwise equal to the
// update followed by apply_texels; the reference runs both as plain loops.
void update_direction_and_apply_texels(GridShape shape, const std::uint8_t* bits, const double* z, double beta,
                                       double* p, double* q, double* row_dot,
                                       Execution execution = Execution::parallel);
void update_direction_and_apply_texels_reference(GridShape shape, const std::uint8_t* bits, const double* z,
                                                 double beta, double* p, double* q, double* row_dot);

}  // namespace dgtex::kernels
