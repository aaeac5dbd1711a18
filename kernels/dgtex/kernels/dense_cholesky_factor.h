#pragma once
// A = L L^T in place for a small dense symmetric matrix: SparseCholesky's dense path (up to
// 512 unknowns), the factorisation of the step solver and of the basis projection's mass
// matrix for the cut single elements of the Table 5.1 scenes (36-498 unknowns, a new factor
// at almost every basis change). A is n x n column-major with leading dimension
// ld >= dense_cholesky_padded_rows(n); its lower triangle is read and overwritten with L.
// The strict upper triangle and the rows n..ld-1 are scratch: the paths compute whole
// vectors of rows there instead of a scalar remainder, so they must hold finite values
// (zeros, say) and end with unspecified ones.
//
// Order of the operations (every path, and the reference, round exactly alike: no FMA
// contraction, lanes never mix): left-looking, column by column,
//   s_i = A_ij - L_i0 L_j0 - L_i1 L_j1 - ... - L_i,j-1 L_j,j-1   (i >= j, k ascending),
//   L_jj = sqrt(s_j), L_ij = s_i / L_jj.
// The paths take 4 columns per pass over the columns to their left (each L_ik loaded once
// for 4 products instead of 4 times), two registers of rows at a time (8 rows each with
// AVX-512, 4 with AVX2, 2 on the baseline); every entry still sees the products above in
// the order above. Why its own loops: Eigen's blocked LLT in this baseline x86-64 build
// uses 2 lanes and costs more in bookkeeping than arithmetic at these sizes, and says only
// whether it failed, not where; LAPACK's dpotrf (serial OpenBLAS) is as fast only from
// ~450 unknowns on and needs a process-wide lock.
// Keeps nothing; thread-safe on distinct A. Units: L has the square root of A's.
#include "dgtex/kernels/vector_path.h"

namespace dgtex::kernels {

// The leading dimension the paths need: n rounded up to 8, plus 8.
int dense_cholesky_padded_rows(int n);
// Returns -1 when A is positive definite, otherwise the first column whose pivot s_j is
// not positive or not finite (A's lower triangle then holds partial results).
int dense_cholesky_factor(int n, int ld, double* A, VectorPath path = VectorPath::best);
// The same operations one entry at a time (any ld >= n; only the lower triangle is touched).
int dense_cholesky_factor_reference(int n, int ld, double* A);

}  // namespace dgtex::kernels
