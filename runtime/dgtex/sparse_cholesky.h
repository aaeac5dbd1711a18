#pragma once
// Sparse Cholesky factorisation through CHOLMOD (supernodal). The symbolic analysis (fill
// reducing ordering, supernodes) is done once per pattern and reused by every numeric
// factorisation with the same pattern, as in a time loop. Small, mostly dense systems (a
// cut single element) are factored densely instead (dgtex's own kernel, dense_cholesky.h):
// up to 128 unknowns, or up to 512 with at least a quarter of the lower triangle stored.
//
// Matrices are given as the LOWER triangle in compressed-column form (n x n, 0-based).
// SparseCholesky owns the CHOLMOD workspace, analysis and factor (not copyable). Not
// thread-safe for concurrent calls on one instance; distinct instances are independent.
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace dgtex {

// Thrown when the matrix is not positive definite (CHOLMOD hit a non-positive pivot).
class NotPositiveDefinite : public std::runtime_error {
 public:
  NotPositiveDefinite(const std::string& what, int column) : std::runtime_error(what), column_(column) {}
  // The matrix's column (its own order, not the factor's) where the factorisation failed:
  // one of the unknowns of the mode that lost definiteness, where to look for its cause.
  int column() const { return column_; }

 private:
  int column_;
};

class SparseCholesky {
 public:
  // dense_max_unknowns: systems up to this size may be factored densely (0: always CHOLMOD).
  static constexpr int default_dense_max_unknowns = 512;
  explicit SparseCholesky(int dense_max_unknowns = default_dense_max_unknowns);
  // Whether analyze() factors an n x n pattern with `lower_nonzeros` entries in its lower
  // triangle (diagonal included) densely: small, and small enough or filled enough that
  // CHOLMOD's bookkeeping would cost more than the arithmetic (dense_cholesky.h).
  static bool factors_densely(int n, std::int64_t lower_nonzeros,
                              int dense_max_unknowns = default_dense_max_unknowns);
  ~SparseCholesky();
  SparseCholesky(const SparseCholesky&) = delete;
  SparseCholesky& operator=(const SparseCholesky&) = delete;

  // Symbolic analysis of the pattern; values are not needed yet.
  void analyze(int n, const std::vector<int>& column_start, const std::vector<int>& row_index);
  bool analyzed() const;
  // Numeric factorisation with values in the analysed pattern's order.
  void factorize(const std::vector<double>& values);
  // x = A^-1 b.
  void solve(const std::vector<double>& b, std::vector<double>& x) const;
  // A single-precision copy of the current factor (supernodal L in float, the same
  // structure) and x ~= A^-1 b with it, computed in float (own loops, not BLAS):
  // half the memory traffic of solve() (L is ~35 MB in double for the cylinder scene),
  // accurate to ~1e-6 relative times the conditioning, meant as a preconditioner. Disjoint
  // subtrees of the elimination tree run on the OpenMP threads, in a split fixed by the
  // factor's structure, so x is bitwise independent of the thread count. Not safe for
  // concurrent calls on one instance. copy_factor_to_single_precision() must follow
  // each factorize() whose factor solve_single_precision() is to use. A dense factor
  // (small systems) keeps a float copy from dense_single_precision_min_unknowns on
  // (dense_cholesky.h); below that solve_single_precision() is solve().
  static constexpr int dense_single_precision_min_unknowns = 256;
  void copy_factor_to_single_precision();
  void solve_single_precision(const std::vector<double>& b, std::vector<double>& x) const;
  int size() const { return n_; }
  // Non-zeros of the factor L (after factorize).
  std::int64_t factor_nonzeros() const;
  // The pivots of the current factor, L_jj^2, indexed by the matrix's own columns (n; after
  // factorize). A pivot far below its column's diagonal entry A_jj is what rounding left of
  // a singular direction (a mechanism), which a factorisation need not refuse.
  std::vector<double> pivots() const;
  // Whether the analysed pattern is factored densely rather than by CHOLMOD.
  bool dense() const;

 private:
  // After a supernodal analysis with a fill-reducing order: Impl::permuted and its sources.
  void build_permuted_lower();
  struct Impl;
  std::unique_ptr<Impl> impl_;
  void build_solve_schedule();  // parallel schedule of solve_single_precision (per analysis)
  int n_ = 0;
  int dense_max_unknowns_ = 0;
};

}  // namespace dgtex
