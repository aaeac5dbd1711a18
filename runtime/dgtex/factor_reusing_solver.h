#pragma once
// Solves a sequence of slowly changing SPD systems A_k x = b_k (the corotated dynamic step
// matrix M + dt D + dt^2 R K R^T) by conjugate gradients preconditioned with the Cholesky
// factor of an earlier A_j, refactorising only when that preconditioner has gone stale.
//
// Why: for the cylinder buckling scene (8525 free DOFs) nnz(L) is ~3.4M whatever the
// ordering (METIS, AMD, NESDIS are within 10%: the DG edge terms couple every node to ~80
// others), so one factorisation costs ~2 GFLOP (~150 ms) while one forward/backward solve
// costs ~1.5-3 ms. Under corotation A_k changes slowly, so A_j^-1 A_k stays close to I:
// PCG needs 2-3 solves per step right after a factorisation, ~8 some 20 steps later
// (the membrane term dt^2 K is ~30x the mass at the highest modes, so small rotation
// changes matter; rotating the old factor along per-node rotations did not help).
//
// Contract: the returned x satisfies ||b - A x||_2 <= relative_tolerance * ||b||_2 over the
// free DOFs (the PCG recurrence residual; round-off may let the true one differ slightly),
// or the solver throws. If max_iterations do not suffice, A_k itself is factorised and PCG
// restarts from the same guess with that exact factor.
// Refactorisation happens when a solve took more than `refactor_after_iterations`
// iterations (the next system is factorised) or did not converge in `max_iterations`.
//
// Determinism: the factor (CHOLMOD with serial BLAS), the block matrix-vector product
// and the dot products (fixed chunking, summed in a fixed order) do not depend on the
// number of threads, and neither does the refactorisation decision, so x is bitwise
// identical for any thread count.
// FactorReusingSolver owns its work vectors and statistics and keeps references to the
// pattern, the free-DOF system and the mass blocks (all must outlive it); the Cholesky
// factor is the caller's, passed to each solve. Not thread-safe; a solve uses all OpenMP
// threads. Units: those of the system (SI: kg, N/m, N).
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "dgtex/block_assembly.h"
#include "dgtex/free_dof_system.h"
#include "dgtex/sparse_cholesky.h"

namespace dgtex {

struct FactorReuseOptions {
  // On ||b - A x|| / ||b|| over the free DOFs (the PCG recurrence residual). 1e-8 keeps the
  // cylinder scene's probe within 5e-10 (relative) of refactorising every step.
  double relative_tolerance = 1e-8;
  // A solve slower than this factorises the next system. Measured on the cylinder scene
  // (50 steps, 1 thread; `dgtex bench shell --refactor-after N`): N = 6: 8 factorisations +
  // 208 iterations, solve 45 ms/step; 8: 5 + 249, 37 ms; 12: 3 + 310, 35 ms; 16: 2 + 365,
  // 38 ms. One factorisation costs ~60 preconditioner applications, so 8-12 is the optimum.
  // Over 100 steps (the buckling develops) N = 8: 18 factorisations + 546 iterations; 12:
  // 11 + 730; 16: 7 + 910; 24: 5 + 1180. At ~150 ms per factorisation and ~3.3 ms per
  // iteration (1 thread) 12 and 16 cost ~10% less than 8, 24 more: 12.
  int refactor_after_iterations = 12;
  int max_iterations = 40;            // beyond this, factorise the current system now
  // Apply the preconditioner with a float copy of L (SparseCholesky::solve_single_precision):
  // half the memory traffic per iteration; the residual bound is unchanged (the PCG
  // arithmetic stays in double, only the preconditioner is approximated further).
  bool single_precision_preconditioner = true;
};

struct FactorReuseStatistics {
  long solves = 0;
  long factorizations = 0;
  long iterations = 0;           // PCG iterations (preconditioner applications) in total
  int last_iterations = 0;
  double factorize_ms = 0;       // wall time in numeric factorisations
  double precondition_ms = 0;    // wall time in preconditioner applications (L^-T L^-1 r)
  double last_relative_residual = 0;
};

// The step matrix A = mass_scale M + stiffness_scale K (blocks in the solver's pattern). A is
// never formed: a product reads K once and M through its scalar diagonal (the shell's
// consistent mass has blocks m_ab I3), ~10% more traffic than a product with a formed A
// but without the pass over three block arrays (26 MB for the cylinder) that forms it.
struct ScaledBlockSum {
  double mass_scale = 1;
  const std::vector<double>* stiffness = nullptr;  // num_blocks x 9
  double stiffness_scale = 0;
};

class FactorReusingSolver {
 public:
  // mass: num_blocks x 9 (kept by reference: it must outlive the solver).
  FactorReusingSolver(const BlockAssembly& pattern, const FreeDofSystem& system, const std::vector<double>& mass,
                      FactorReuseOptions options = {});

  // b: #dofs (fixed entries ignored). x: #dofs, in: initial guess, out: solution with
  // fixed entries zero. `cholesky` is the factorisation it reuses and refreshes (analysed
  // on first use). Throws NotPositiveDefinite from a factorisation.
  // stiffness_times_x (optional): K times the initial guess x, when the caller has it (e.g.
  // from block_multiply_pair): saves one pass over K; the result is bitwise the same.
  void solve(const ScaledBlockSum& A, const std::vector<double>& b, std::vector<double>& x, SparseCholesky& cholesky,
             const std::vector<double>* stiffness_times_x = nullptr);

  // y = M x (the mass of the constructor), through its scalar diagonal when isotropic.
  void multiply_mass(const std::vector<double>& x, std::vector<double>& y) const;

  // Forces a factorisation at the next solve (e.g. the matrix changed abruptly).
  void invalidate() { factor_current_ = false; }
  const FactorReuseStatistics& statistics() const { return stats_; }
  const FactorReuseOptions& options() const { return options_; }
  void set_options(const FactorReuseOptions& options) { options_ = options; }

 private:
  const BlockAssembly& pattern_;
  const FreeDofSystem& system_;
  const std::vector<double>& mass_;
  std::vector<double> mass_scalar_;  // m_ab per block when every block is m_ab I3, else empty
  FactorReuseOptions options_;
  FactorReuseStatistics stats_;
  bool factor_current_ = false;  // cholesky holds a factor of some earlier A
  std::vector<double> values_, r_, z_, p_, q_, reduced_in_, reduced_out_, b_free_, guess_;
  std::vector<char> free_;

  void factorize(const ScaledBlockSum& A, SparseCholesky& cholesky);
  void precondition(const SparseCholesky& cholesky, const std::vector<double>& r, std::vector<double>& z);
  // y = A x over free DOFs (fixed entries of y set to zero).
  void multiply(const ScaledBlockSum& A, const std::vector<double>& x, std::vector<double>& y) const;
  // Runs PCG from x; returns iterations used, or -1 if max_iterations did not suffice.
  // kx: K x for the initial x, or null (then computed).
  int pcg(const ScaledBlockSum& A, const std::vector<double>& b, std::vector<double>& x,
          const SparseCholesky& cholesky, double& relative_residual, const std::vector<double>* kx);
};

// Sum of x[i] * y[i] in a fixed order, independent of the thread count.
double deterministic_dot(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace dgtex
