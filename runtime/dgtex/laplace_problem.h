#pragma once
// The harmonic (Laplace) problem on a texel tile, shared by all its solvers: see
// dgtex/kernels/multigrid_unknowns.h for the discrete equations. Residuals are always
// measured the same way so solvers compare at equal accuracy: relative residual
// ||b - A x||_2 / ||b||_2 of the reduced SPD system (unknowns = free texels of components
// with Dirichlet data, b = sum of coupled Dirichlet neighbours' values).
// Value types and pure functions (thread-safe). Residuals are dimensionless, times in ms.
#include <cstddef>  // texel_grid.h uses size_t without including it
#include <cstdint>
#include <vector>

#include "dgtex/kernels/texel_grid.h"

namespace dgtex {

struct LaplaceSolveStats {
  int iterations = 0;             // cycles / iterations (0 for a direct solve)
  double relative_residual = 0;   // ||b - A x|| / ||b|| at the end (0 when b = 0)
  double ms = 0;                  // wall time of the whole call
};

// Throws std::invalid_argument unless the tile is non-empty and its arrays have width*height entries.
void validate_laplace_tile(const kernels::TexelTile& tile);

// ||b - A x|| and ||b|| of the reduced system for the current tile.values, given the
// classification bytes of kernels::classify_laplace_texels.
struct LaplaceResidualNorms { double residual = 0; double rhs = 0; double relative() const { return rhs > 0 ? residual / rhs : residual; } };
LaplaceResidualNorms laplace_residual_norms(const kernels::TexelTile& tile, const std::vector<std::uint8_t>& bits);

}  // namespace dgtex
