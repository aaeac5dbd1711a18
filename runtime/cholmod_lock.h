#pragma once
// Internal: one process-wide lock held around every CHOLMOD analysis, factorisation and
// solve in dgtex (SparseCholesky and Eigen's CholmodSupernodalLLT alike) and every LAPACK
// call (the dense factorisation of small systems, dense_cholesky.cpp), except the texel
// Laplacians of mesh_texel_laplace.cpp (simplicial with AMD) and the multigrid's coarsest
// level (simplicial in its own order, laplace_multigrid.cpp): they call neither BLAS nor
// METIS, so the two hazards below cannot arise there.
// Why: independent simulations may run on several threads of one process (one SceneRun
// per thread), but (1) Debian's libopenblas0-serial, the BLAS that CHOLMOD calls, is built
// without locking and collided under concurrent calls (a spurious "not positive definite"
// with two chad runs at once), and (2) METIS, CHOLMOD's ordering, draws from one global
// random generator, so concurrent orderings interleaved its draws and the results of two
// cylinder runs at once differed from solo runs (1e-11, and 1e-7 with the PCG steps).
// Serialised, every run orders and factorises exactly as it would alone. The cost: CHOLMOD
// calls of different simulations wait for each other; nothing else is serialised.
#include <mutex>

namespace dgtex::detail {

std::unique_lock<std::mutex> lock_cholmod();

}  // namespace dgtex::detail
