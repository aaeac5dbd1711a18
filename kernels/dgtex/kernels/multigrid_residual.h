#pragma once
// Multigrid residuals r = b - A x (0 at nodes without unknown). Each also writes the sum
// of r^2 of every grid row into row_norm2[j] (summed left to right), so callers form
// ||r||^2 by adding the rows in order: a norm that does not depend on the thread count.
#include <cstdint>

#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/multigrid_grid.h"

namespace dgtex::kernels {

// Level 0 (5-point texel operator, LaplaceTexelBits). row_norm2 may be null.
void residual_texels(GridShape shape, const std::uint8_t* bits, const double* b, const double* x, double* r,
                     double* row_norm2, Execution execution = Execution::parallel);
void residual_texels_reference(GridShape shape, const std::uint8_t* bits, const double* b, const double* x, double* r,
                               double* row_norm2);

// Coarse levels (9-point). row_norm2 may be null.
void residual_stencil9(GridShape shape, Stencil9View a, const double* b, const double* x, double* r,
                       double* row_norm2, Execution execution = Execution::parallel);
void residual_stencil9_reference(GridShape shape, Stencil9View a, const double* b, const double* x, double* r,
                                 double* row_norm2);

// y = A x on level 0 (for conjugate gradients); row_dot[j] = sum over row j of x * y.
void apply_texels(GridShape shape, const std::uint8_t* bits, const double* x, double* y, double* row_dot,
                  Execution execution = Execution::parallel);

}  // namespace dgtex::kernels
