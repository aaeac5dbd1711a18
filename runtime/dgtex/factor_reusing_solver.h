#pragma once
// Solves a sequence of slowly changing SPD systems A_k x = b_k (the corotated dynamic step
// matrix M + dt D + dt^2 R K R^T) by conjugate gradients preconditioned with the Cholesky
// factor of an earlier A_j, refactorising only when that preconditioner has gone stale.
//
// Why: for the cylinder buckling scene (8525 free DOFs) nnz(L) is ~4.4M whatever the
// ordering (METIS, AMD, NESDIS are within 10%: the DG edge terms couple every node to ~80
// others), so one factorisation costs ~2 GFLOP (~250 ms) while one forward/backward solve
// costs ~2-3 ms. Under corotation A_k changes slowly, so A_j^-1 A_k stays close to I:
// PCG needs 2-3 solves per step right after a factorisation, ~8 some 20 steps later
// (the membrane term dt^2 K is ~30x the mass at the highest modes, so small rotation
// changes matter; rotating the old factor along per-node rotations did not help).
//
// Element-local preconditioner (the default): the factor is taken of A with only the
// blocks that couple two nodes of one element (where the consistent mass is non-zero),
// i.e. without the DG edge terms' couplings across an edge. Those terms act on the
// rotation jump (bending, ~t^3), small next to mass and membrane stiffness, so PCG needs
// only a few more iterations, but nnz(L) drops ~4x (cylinder: 1.15M instead of 4.36M):
// a factorisation costs ~70 ms instead of ~220, an application ~0.65 ms instead of 2-3.
// It is a heuristic, so it is tried only where the couplings it drops are small next to A's
// diagonal (element_local_dropped_radius, judged on the first matrix factorised:
// FactorReuseOptions::element_local_max_dropped_radius), and it falls back to the whole
// pattern for the rest of the run when its matrix is not positive definite or a fresh
// element-local factor does not reach the tolerance within max_iterations
// (statistics().element_local_fallbacks counts it).
// Only where the whole pattern's factor is sparse: a small system that SparseCholesky
// factors densely (SparseCholesky::factors_densely) has a dense factor either way, so the
// element-local one would only cost iterations (chad, 126 DOFs: 1175 PCG iterations over
// its run with it, 775 without).
//
// Contract: the returned x satisfies ||b - A x||_2 <= relative_tolerance * ||b||_2 over the
// free DOFs (the PCG recurrence residual; round-off may let the true one differ slightly),
// or the solver throws. If max_iterations do not suffice with an old factor, A_k itself is
// factorised and PCG restarts from the same guess; if a fresh element-local factor does
// not suffice either, the whole pattern of A_k is.
// Refactorisation happens when a solve took more than `refactor_after_iterations`
// iterations (`large_dense_refactor_after_iterations` for dense systems of 256 unknowns or
// more) or did not converge in `max_iterations` (then A_k at once). In the first case
// the matrix of A_k itself (element-local or whole pattern) is factorised while the caller
// assembles A_k+1 (FactorReuseOptions::overlap_factorization, factorize_pending()): CHOLMOD
// factorises on one core, and waiting for it cost ~4 ms of the cylinder scene's ~22 ms step
// (2 threads). The whole pattern's pending factor is the one passed to that solve. A
// pending dense factor (dense_factorization_pending(): ~1 ms at 450 unknowns) is
// factorised in turn before the assembly instead (ShellSimulation::step): beside it the
// assembly would run on one thread fewer for longer than the factorisation takes.
//
// Dependent nodes (the system's, FreeDofSystem): the solve runs over the free DOFs of
// T^T A T; b is collected (T^T b) and x distributed (x = T x_free) before it returns, and
// the element-local preconditioner is not used (its blocks would not hold the ties).
//
// Determinism: the factor (CHOLMOD with serial BLAS), the block matrix-vector product
// and the dot products (fixed chunking, summed in a fixed order) do not depend on the
// number of threads, and neither does the refactorisation decision, so x is bitwise
// identical for any thread count.
// FactorReusingSolver owns its work vectors, statistics and the element-local factor and
// keeps references to the pattern, the free-DOF system and the mass blocks (all must
// outlive it); the factor of the whole pattern is the caller's, passed to each solve.
// Not thread-safe; a solve uses all OpenMP threads. Units: those of the system (SI: kg,
// N/m, N).
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <vector>

#include "dgtex/block_assembly.h"
#include "dgtex/free_dof_system.h"
#include "dgtex/sparse_cholesky.h"

namespace dgtex {

// Which couplings of A the preconditioner factorises (see above).
enum class PreconditionerPattern { full, element_local };

struct FactorReuseOptions {
  // On ||b - A x|| / ||b|| over the free DOFs (the PCG recurrence residual). 1e-8 keeps the
  // cylinder scene's probe within 5e-10 (relative) of refactorising every step.
  double relative_tolerance = 1e-8;
  // A solve slower than this factorises the next system. Measured on the cylinder scene
  // (100 steps, 1 thread, CPU time per step; `dgtex bench shell --refactor-after N`), with
  // the element-local preconditioner and the linear initial guess: N = 6: 27 factorisations + 595 iterations, 44-46 ms;
  // 8: 19 + 664, 39-47 ms; 10: 14 + 741, 40-42 ms; 12: 11 + 821, 41-42 ms; 16: 8 + 967,
  // 40-43 ms; 24: 5 + 1257, 42-44 ms (a shared machine: the spread is noise). Flat from 8
  // to 20; 12 also was the optimum of the whole-pattern factor (11 + 730, 61-64 ms).
  int refactor_after_iterations = 12;
  // The same for systems factored densely with a float copy of the factor (256 to 512
  // unknowns, SparseCholesky::dense_single_precision_min_unknowns: the accordion's 450).
  // There an iteration reads K and L from the L3 cache (~2.4 MB, ~70 us), while the dense
  // factorisation (~1 ms) runs beside the next assembly. The accordion (200 steps, three
  // alternating runs of each, `dgtex bench scenes --scenes accordion`, 2-core machine): 3
  // gives 21 factorisations + 565 iterations, solve 0.32-0.36 ms a step, against 1 + 945
  // and 0.46-0.47 ms with 12; assembly 6.9-7.2 against 7.2-7.4 ms, CPU 11.6-12.0 against
  // 12.6-13.1 ms a step. 4: 5 + 713, 0.44 ms; 2: 49 + 453, 0.38 ms.
  int large_dense_refactor_after_iterations = 3;
  int max_iterations = 40;            // beyond this, factorise the current system now
  // Apply the preconditioner with a float copy of L (SparseCholesky::solve_single_precision):
  // half the memory traffic per iteration; the residual bound is unchanged (the PCG
  // arithmetic stays in double, only the preconditioner is approximated further).
  bool single_precision_preconditioner = true;
  PreconditionerPattern preconditioner_pattern = PreconditionerPattern::element_local;
  // The element-local pattern only where its dropped couplings' radius
  // (element_local_dropped_radius) in the first matrix factorised is at most this; above it
  // the whole pattern from the start. Measured (radius; element-local against whole-pattern
  // preconditioning): the cylinder scene 0.34, its factor ~4x sparser, ~3x faster to
  // factorise; the fracture scene's plate without cuts at time steps 1e-4 s: 0.52,
  // converging but 145 against 46 PCG iterations in 40 steps (4.1 against 3.9 ms a step);
  // 3e-4 s: 0.80, 377 against 80 (three factorisations against one); 5e-4 s: 0.99, and
  // the fracture scene itself (1e-3 s, cut): 2.9, not positive definite (a wasted analysis
  // and factorisation, ~4 ms of its first step).
  double element_local_max_dropped_radius = 0.5;
  // A solve slower than refactor_after_iterations gathers its own matrix A_k (element-local
  // or whole pattern) and leaves its factorisation pending, to be run by factorize_pending()
  // while the caller assembles the next matrix (on a thread of its own: CHOLMOD runs on one
  // core), or else at the start of the next solve. That solve then starts from a factor one
  // step old, judged like any reused factor. false: the next solve factorises its own A_k+1.
  bool overlap_factorization = true;
};

struct FactorReuseStatistics {
  long solves = 0;
  long factorizations = 0;
  long iterations = 0;           // PCG iterations (preconditioner applications) in total
  int last_iterations = 0;
  double factorize_ms = 0;       // wall time in numeric factorisations
  double precondition_ms = 0;    // wall time in preconditioner applications (L^-T L^-1 r)
  double last_relative_residual = 0;
  // Element-local preconditioning given up for the whole pattern (0 or 1): its matrix was
  // not positive definite, or a fresh factor of it did not converge in max_iterations.
  int element_local_fallbacks = 0;
  // Solves whose reused factor did not converge in max_iterations (those iterations wasted,
  // then A_k factorised at once). Many in a row: A changes fast from step to step, e.g. a
  // nearly massless mode that has gone unstable.
  long stale_factor_failures = 0;
};

// a + b for the counters and times; the last_* fields are b's (the later run's).
FactorReuseStatistics operator+(const FactorReuseStatistics& a, const FactorReuseStatistics& b);

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
  // mass: num_blocks x 9 (kept by reference: it must outlive the solver). Throws
  // std::invalid_argument for options set_options refuses.
  FactorReusingSolver(const BlockAssembly& pattern, const FreeDofSystem& system, const std::vector<double>& mass,
                      FactorReuseOptions options = {});
  // The three are kept by reference: temporaries would dangle, const ones too.
  FactorReusingSolver(BlockAssembly&&, const FreeDofSystem&, const std::vector<double>&, FactorReuseOptions = {}) = delete;
  FactorReusingSolver(const BlockAssembly&, FreeDofSystem&&, const std::vector<double>&, FactorReuseOptions = {}) = delete;
  FactorReusingSolver(const BlockAssembly&, const FreeDofSystem&, std::vector<double>&&, FactorReuseOptions = {}) = delete;
  FactorReusingSolver(const BlockAssembly&&, const FreeDofSystem&, const std::vector<double>&,
                      FactorReuseOptions = {}) = delete;
  FactorReusingSolver(const BlockAssembly&, const FreeDofSystem&&, const std::vector<double>&,
                      FactorReuseOptions = {}) = delete;
  FactorReusingSolver(const BlockAssembly&, const FreeDofSystem&, const std::vector<double>&&,
                      FactorReuseOptions = {}) = delete;

  // b: #dofs (fixed entries ignored). x: #dofs, in: initial guess, out: solution with
  // fixed entries zero. `cholesky` is the factorisation of the whole pattern it reuses and
  // refreshes (analysed on first use) when the preconditioner pattern is full or after a
  // fallback; the element-local factor is the solver's own. Throws NotPositiveDefinite from a
  // factorisation, std::runtime_error for a b that is not finite or no convergence even with
  // a fresh factor, std::invalid_argument for b, x or stiffness_times_x of another size.
  // stiffness_times_x (optional): K times the initial guess x, when the caller has it (e.g.
  // from block_multiply_pair): saves one pass over K; the result is bitwise the same.
  void solve(const ScaledBlockSum& A, const std::vector<double>& b, std::vector<double>& x, SparseCholesky& cholesky,
             const std::vector<double>* stiffness_times_x = nullptr);

  // y = M x (the mass of the constructor), through its scalar diagonal when isotropic.
  void multiply_mass(const std::vector<double>& x, std::vector<double>& y) const;

  // Forces a factorisation at the next solve (e.g. the matrix changed abruptly).
  void invalidate() {
    factor_current_ = false;
    factorization_pending_ = false;
  }
  // A factorisation left for factorize_pending() (options().overlap_factorization).
  bool factorization_pending() const { return factorization_pending_; }
  // ... of a dense factor (SparseCholesky::factors_densely: about 1 ms at 450 unknowns),
  // cheap enough to run in turn before an assembly instead of beside it.
  bool dense_factorization_pending() const { return factorization_pending_ && whole_pattern_dense_; }
  // Factorises the matrix gathered by the last solve, if one is pending. Needs no OpenMP
  // team (CHOLMOD with serial BLAS): safe to run beside code that touches neither this
  // solver nor CHOLMOD. An element-local matrix that is not positive definite switches to
  // the whole pattern (then the next solve factorises its own matrix); a whole-pattern one
  // leaves the next solve to factorise its own matrix (and report it). The whole pattern is
  // factorised into the `cholesky` of the solve that left it pending: it must still exist.
  void factorize_pending();
  // True while the preconditioner is the element-local factor (not ruled out by its dropped
  // radius, no fallback happened).
  bool element_local() const { return use_element_local_; }
  // element_local_dropped_radius of the first matrix factorised while the element-local
  // pattern was chosen; NaN before (or when it never was).
  double element_local_dropped_radius() const { return element_local_dropped_radius_; }
  // Non-zeros of the element-local factor L (0 before its first factorisation).
  std::int64_t element_local_factor_nonzeros() const {
    return element_local_factor_ ? element_local_factor_->factor_nonzeros() : 0;
  }
  const FactorReuseStatistics& statistics() const { return stats_; }
  const FactorReuseOptions& options() const { return options_; }
  // A change of the preconditioner pattern takes effect with a factorisation at the next solve.
  // std::invalid_argument naming the field for a relative_tolerance outside (0, 1),
  // max_iterations < 1, negative refactor_after counts or a negative radius.
  void set_options(const FactorReuseOptions& options);

 private:
  const BlockAssembly& pattern_;
  const FreeDofSystem& system_;
  const std::vector<double>& mass_;
  std::vector<double> mass_scalar_;  // m_ab per block when every block is m_ab I3, else empty
  FactorReuseOptions options_;
  FactorReuseStatistics stats_;
  bool factor_current_ = false;  // cholesky holds a factor of some earlier A
  bool factorization_pending_ = false;  // values_ holds an A_k (element-local or whole pattern) to factorise
  std::vector<double> values_, r_, z_, p_, q_, reduced_in_, reduced_out_, b_free_, guess_;
  // Scratch of the block products: the spread vector (kernels/block_product.h), K x and M x.
  mutable std::vector<double> spread_, k_product_, m_product_;
  std::vector<char> free_;    // per DOF: an unknown of the system (neither fixed nor dependent)
  std::vector<char> summed_;  // per DOF: free or dependent, the rows A x sums before collecting
  SparseCholesky* pending_factor_ = nullptr;  // whole pattern: the caller's factor that factorize_pending() refreshes
  // Element-local preconditioner: the blocks it keeps, its system and factor (built on
  // first use), and whether it is in use.
  std::vector<char> element_local_blocks_;
  std::unique_ptr<FreeDofSystem> element_local_system_;
  std::unique_ptr<SparseCholesky> element_local_factor_;
  bool element_local_differs_ = false;  // some coupling block is not element-local
  bool whole_pattern_dense_ = false;     // SparseCholesky factors the whole pattern densely
  bool large_dense_ = false;             // ... and keeps a float copy of the factor
  bool use_element_local_ = false;
  double element_local_dropped_radius_ = std::numeric_limits<double>::quiet_NaN();  // until judged

  // Factorises A (element-local, or the whole pattern into `cholesky`); an element-local
  // matrix that is not positive definite switches to the whole pattern.
  void factorize(const ScaledBlockSum& A, SparseCholesky& cholesky);
  // The element-local matrix of A into values_ (its system built on first use).
  void gather_element_local(const ScaledBlockSum& A);
  // Numeric factorisation of values_ into the element-local factor (+ float copy).
  void factorize_element_local_values();
  // Numeric factorisation of values_ (the whole pattern) into `cholesky` (+ float copy).
  void factorize_full_values(SparseCholesky& cholesky);
  void fall_back_to_full_pattern();
  // At the first factorisation with the element-local pattern: rules it out for good when
  // A's dropped radius exceeds options_.element_local_max_dropped_radius.
  void judge_element_local(const ScaledBlockSum& A);
  void precondition(const SparseCholesky& cholesky, const std::vector<double>& r, std::vector<double>& z);
  // spread_ = x spread for the block product kernels.
  void spread(const std::vector<double>& x) const;
  // Rows [first, last) of M x, x in spread_.
  void multiply_mass_rows(std::int64_t first, std::int64_t last, double* y) const;
  // y = T^T A x over free DOFs, x = T x_free (fixed and dependent entries of y zero).
  void multiply(const ScaledBlockSum& A, const std::vector<double>& x, std::vector<double>& y) const;
  // Runs PCG from x; returns iterations used, or -1 if max_iterations did not suffice.
  // kx: K x for the initial x, or null (then computed).
  int pcg(const ScaledBlockSum& A, const std::vector<double>& b, std::vector<double>& x,
          const SparseCholesky& cholesky, double& relative_residual, const std::vector<double>* kx);
};

// Per block of the pattern (mass: num_blocks x 9): 1 where the two nodes belong to one
// element, i.e. the consistent-mass block is non-zero; the DG edge terms' couplings across
// an edge have none. The pattern of the element-local preconditioner.
std::vector<char> element_local_blocks(const std::vector<double>& mass);

// How far the element-local pattern is from A: the largest Gershgorin radius of the couplings
// it drops (blocks with kept[k] == 0) in A scaled to a unit diagonal, i.e. the maximum over
// free DOFs i of sum_j |A_ij| / sqrt(A_ii A_jj) over the dropped entries to free DOFs j
// (free: per DOF, 1 for free). By Gershgorin the dropped part lies between -radius D and
// radius D in the Loewner order (D: A's diagonal), so the element-local matrix is at least
// A - radius D; the radius grows as the dropped stiffness couplings (dt^2 K across an edge)
// outweigh the mass they are added to. Infinite when a free diagonal entry of A is not
// positive. Independent of the thread count (a maximum).
double element_local_dropped_radius(const BlockAssembly& pattern, const std::vector<char>& kept,
                                    const std::vector<char>& free, const std::vector<double>& mass,
                                    const ScaledBlockSum& A);

// Sum of x[i] * y[i] in a fixed order, independent of the thread count.
double deterministic_dot(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace dgtex
