#pragma once
// Internal: one process-wide lock held around every CHOLMOD analysis, factorisation and
// solve in dgtex (SparseCholesky and Eigen's CholmodSupernodalLLT alike), except the texel
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
//
// While held, the lock also keeps the OpenMP parallel regions that this thread opens on
// this thread alone (max-active-levels 0, an ICV of the calling thread only). CHOLMOD 3
// (SuiteSparse 5.12) clears and scatters every large supernode in a region of a fixed
// num_threads(4), whatever the program's thread count: on the 2-core machine these
// thousands of small, oversubscribed regions made the fracture scene's first factorisation
// (4116 DOFs) take 35-44 ms instead of 10-12. Factorisations that run beside the assembly
// were spared already, being nested in its active region.
#include <mutex>

namespace dgtex::detail {

class CholmodLock {
 public:
  CholmodLock();
  ~CholmodLock();
  CholmodLock(const CholmodLock&) = delete;
  CholmodLock& operator=(const CholmodLock&) = delete;

 private:
  std::unique_lock<std::mutex> lock_;
  int max_active_levels_;  // this thread's, restored on release
};

inline CholmodLock lock_cholmod() { return {}; }

// Debian's OpenBLAS takes a workspace of 128 MiB (its BUFFER_SIZE on x86-64) at its first
// call, and when malloc refuses it, as under a `ulimit -v` near the process's size, it
// retries forever: the cylinder under `ulimit -v 300000` spun at 100 % of a core in its first
// factorisation instead of failing. Call while holding the lock, before a CHOLMOD call that
// may reach BLAS (a supernodal factorisation). Its first call in the process checks the
// address space left and has OpenBLAS take its workspace at once (a 1 x 1 supernodal
// factorisation), which it keeps; later calls return at once. Throws std::runtime_error
// naming the room needed and left (nothing is taken then, and the next call checks again).
void reserve_blas_workspace(const CholmodLock& held);

// What reserve_blas_workspace asks to be left: the workspace and a margin for the arena
// glibc may map for a thread's first allocation.
inline constexpr long long kBlasWorkspaceAddressSpace = 192LL << 20;

}  // namespace dgtex::detail
