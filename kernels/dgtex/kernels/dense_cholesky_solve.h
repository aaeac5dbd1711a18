#pragma once
// x = L^-T L^-1 b with a dense Cholesky factor L: the preconditioner of the corotated step
// for small systems (a cut single element: 39-498 unknowns, factored densely; the accordion
// applies it 5 times a step). L is n x n column-major with leading dimension ld >= n, its
// lower triangle used.
//
// Order of the operations (every path, and the reference, round exactly alike: no FMA
// contraction, lanes never mix): forward, column by column, y_j = y_j / L_jj and then
// y_i = y_i - L_ij y_j for i > j (the paths take 8 columns per pass over y, each entry
// still updated in column order: one load and store of y_i per 8 columns); backward,
// from the last column, x_j = (y_j - d_j) / L_jj with d_j = sum_{i > j} L_ij x_i summed
// in 8 lanes (term q = i - j - 1 in lane q mod 8, each lane in order of q from 0), the
// lanes added as l + 4, then l + 2, l + 1 (8 lanes, not 16: in the scenes the sweeps wait
// on memory, and 16 cost more on short columns).
// Both sweeps read the same columns, so the backward one finds much of L still in cache
// (a transposed copy for column updates there was faster alone but slower in the scenes:
// twice the memory). Why its own loops: Eigen's triangular solves in this baseline x86-64
// build use 2 lanes; these have a path for AVX-512, AVX2 and the baseline.
// Keeps nothing; thread-safe on distinct x. Units: x has b's over L's squared.
#include "dgtex/kernels/vector_path.h"

namespace dgtex::kernels {

// x holds b on entry, the solution on return.
void dense_cholesky_solve(int n, int ld, const double* L, double* x, VectorPath path = VectorPath::best);
// The same with L rounded to float (the stale preconditioner of large dense systems: half
// the bytes to read). x stays in double and each entry of L is widened exactly, so only the
// rounding of L differs: the operations and their order are those above.
void dense_cholesky_solve(int n, int ld, const float* L, double* x, VectorPath path = VectorPath::best);
// The same operations one entry at a time.
void dense_cholesky_solve_reference(int n, int ld, const double* L, double* x);
void dense_cholesky_solve_reference(int n, int ld, const float* L, double* x);

}  // namespace dgtex::kernels
