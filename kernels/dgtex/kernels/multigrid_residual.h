#pragma once
// Multigrid residuals r = b - A x (0 at nodes without unknown). Each also writes the sum
// of r^2 of every grid row into row_norm2[j] (summed left to right), so callers form
// ||r||^2 by adding the rows in order: a norm that does not depend on the thread count.
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

// Coarse levels (9-point). row_norm2 may be null.
void residual_stencil9(GridShape shape, Stencil9View a, const double* b, const double* x, double* r,
                       double* row_norm2, Execution execution = Execution::parallel);
void residual_stencil9_reference(GridShape shape, Stencil9View a, const double* b, const double* x, double* r,
                                 double* row_norm2);

// y = A x on level 0 (for conjugate gradients); row_dot[j] = sum over row j of x * y.
void apply_texels(GridShape shape, const std::uint8_t* bits, const double* x, double* y, double* row_dot,
                  Execution execution = Execution::parallel);

// Conjugate-gradient step on level 0 in one streaming pass: p = z + beta p, then q = A p
// and row_dot[j] = sum over row j of p * q (left to right). Bitwise equal to the update
// followed by apply_texels. The reference does exactly that.
void update_direction_and_apply_texels(GridShape shape, const std::uint8_t* bits, const double* z, double beta,
                                       double* p, double* q, double* row_dot,
                                       Execution execution = Execution::parallel);
void update_direction_and_apply_texels_reference(GridShape shape, const std::uint8_t* bits, const double* z,
                                                 double beta, double* p, double* q, double* row_dot);

}  // namespace dgtex::kernels
