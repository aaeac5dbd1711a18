#pragma once
// Batched 3x3 polar decomposition F = R S: the rotation R of each deformation gradient.
// Arrays hold `count` row-major 3x3 matrices back to back (9 doubles each).
// R is the closest proper rotation to F (det R = +1 even for inverted F): a scaled Newton
// iteration for det F > 0 (the corotated shell's case), else from a 3x3 SVD; each matrix
// is independent, so the parallel batch is bitwise equal to the serial one.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// Dimensionless (deformation gradients and rotations).
#include <cstdint>

#include "dgtex/kernels/forall.h"

namespace dgtex::kernels {

void polar_rotation(const double F[9], double R[9]);
// The reference form, always through the SVD; polar_rotation agrees to ~1e-15.
void polar_rotation_reference(const double F[9], double R[9]);

void polar_decomposition_batch(std::int64_t count, const double* F, double* R,
                               Execution execution = Execution::parallel);

}  // namespace dgtex::kernels
