#pragma once
// Grid transfers between a level and the next coarser one with the operator-dependent
// interpolation P (multigrid_grid.h): restriction b_coarse = P^T r_fine and prolongation
// x_fine += P x_coarse. Both are gathers (each output written by one index), so the
// parallel forms equal the serial ones bit for bit.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// Values are dimensionless.
#include <cstdint>

#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/multigrid_grid.h"

namespace dgtex::kernels {

void restrict_residual(GridShape fine, GridShape coarse, InterpolationView p, const double* r_fine, double* b_coarse,
                       Execution execution = Execution::parallel);
void restrict_residual_reference(GridShape fine, GridShape coarse, InterpolationView p, const double* r_fine,
                                 double* b_coarse);

// Adds the interpolated coarse correction at fine nodes with fine_active != 0 only.
void prolong_correction(GridShape fine, GridShape coarse, InterpolationView p, const double* x_coarse,
                        const std::uint8_t* fine_active, double* x_fine, Execution execution = Execution::parallel);
void prolong_correction_reference(GridShape fine, GridShape coarse, InterpolationView p, const double* x_coarse,
                                  const std::uint8_t* fine_active, double* x_fine);

// Red-black forms for level 0 (red: (i + j) even = the coarse nodes (2I, 2J) and the cell
// centres (2I+1, 2J+1)). restrict_red_residual is P^T r for an r that vanishes at black
// nodes (after a forward red-black sweep, see residual_texels_color) and reads red entries
// only. prolong_correction_red adds P x_coarse at red nodes only: the backward sweep that
// follows starts with the black colour, whose update does not read the old black values.
void restrict_red_residual(GridShape fine, GridShape coarse, InterpolationView p, const double* r_fine,
                           double* b_coarse, Execution execution = Execution::parallel);
void restrict_red_residual_reference(GridShape fine, GridShape coarse, InterpolationView p, const double* r_fine,
                                     double* b_coarse);
void prolong_correction_red(GridShape fine, GridShape coarse, InterpolationView p, const double* x_coarse,
                            const std::uint8_t* fine_active, double* x_fine, Execution execution = Execution::parallel);
void prolong_correction_red_reference(GridShape fine, GridShape coarse, InterpolationView p, const double* x_coarse,
                                      const std::uint8_t* fine_active, double* x_fine);

// Single-precision forms for the float preconditioner cycle (LaplaceMultigridOptions::
// single_precision_min_texels): between float levels the arithmetic is float; between level 0
// (double) and a float level 1, restriction sums in double and rounds once, prolongation
// forms the correction in float and adds it in double.
void restrict_residual(GridShape fine, GridShape coarse, InterpolationViewFloat p, const float* r_fine,
                       float* b_coarse, Execution execution = Execution::parallel);
void restrict_residual_reference(GridShape fine, GridShape coarse, InterpolationViewFloat p, const float* r_fine,
                                 float* b_coarse);
void prolong_correction(GridShape fine, GridShape coarse, InterpolationViewFloat p, const float* x_coarse,
                        const std::uint8_t* fine_active, float* x_fine, Execution execution = Execution::parallel);
void prolong_correction_reference(GridShape fine, GridShape coarse, InterpolationViewFloat p, const float* x_coarse,
                                  const std::uint8_t* fine_active, float* x_fine);
void restrict_red_residual(GridShape fine, GridShape coarse, InterpolationViewFloat p, const double* r_fine,
                           float* b_coarse, Execution execution = Execution::parallel);
void restrict_red_residual_reference(GridShape fine, GridShape coarse, InterpolationViewFloat p, const double* r_fine,
                                     float* b_coarse);
void prolong_correction_red(GridShape fine, GridShape coarse, InterpolationViewFloat p, const float* x_coarse,
                            const std::uint8_t* fine_active, double* x_fine, Execution execution = Execution::parallel);
void prolong_correction_red_reference(GridShape fine, GridShape coarse, InterpolationViewFloat p, const float* x_coarse,
                                      const std::uint8_t* fine_active, double* x_fine);

}  // namespace dgtex::kernels
