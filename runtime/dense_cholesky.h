#pragma once
// Internal to SparseCholesky: the dense factorisation it uses for small systems (a cut
// single element has 39-498 unknowns, mostly coupled to each other). CHOLMOD's analysis,
// supernodal bookkeeping and OpenMP regions cost more there than the arithmetic: n = 39,
// analysis + factorisation 0.03-0.12 ms against 0.007 ms for Eigen's blocked LLT, and 0.2-2
// ms inside a scene step with spinning OpenMP threads; n = 441 (fully dense) 2.9-3.4 ms
// against 2.2 ms (one run of each, 2-core machine). Since session 55 both the
// factorisation and the solves are dgtex's own kernels (kernels::dense_cholesky_factor,
// kernels::dense_cholesky_solve: a path per instruction set, the same bits on each). The
// factorisation replaced Eigen's LLT (below 128 unknowns) and LAPACK's dpotrf (from 128
// on, serial OpenBLAS under the process-wide BLAS lock): about 2x Eigen's LLT at 48-498
// unknowns, 1.4-1.6x dpotrf at 126-168 and as fast at 441-498, in isolation
// (examples/bench_dense_cholesky, session 55). The solves took 3/4 of Eigen's triangular
// solves, which took half of dpotrs (the accordion's preconditioner, 447 unknowns, 60 -> 45
// us an application in its scene).
#include <cstdint>
#include <vector>

namespace dgtex::detail {

class DenseCholesky {
 public:
  // The lower-triangle compressed-column pattern whose values factorize() receives.
  void set_pattern(int n, const std::vector<int>& column_start, const std::vector<int>& row_index);
  // Throws NotPositiveDefinite (column in the matrix's own order) for a non-positive or
  // non-finite pivot.
  void factorize(const std::vector<double>& values);
  void solve(const std::vector<double>& b, std::vector<double>& x) const;
  // From SparseCholesky::dense_single_precision_min_unknowns (256) on, a float copy of L
  // for solve_single_precision() (the preconditioner): the accordion's 450-unknown factor,
  // 0.8 MB of lower triangle in double, no longer stays in a 1 MB L2 cache beside K
  // between the two sweeps. Smaller factors keep solving in double: there a fresh factor
  // solves the system in one PCG iteration, a float copy in two (spiral6 and the slinky:
  // 958 -> 1132 and 862 -> 1061 iterations over their runs in session 25, when every dense
  // factor had a float copy).
  void copy_factor_to_single_precision();
  // x ~= A^-1 b with the float copy where copy_factor_to_single_precision() made one for
  // the current factor, solve() otherwise.
  void solve_single_precision(const std::vector<double>& b, std::vector<double>& x) const;
  std::int64_t factor_nonzeros() const { return static_cast<std::int64_t>(n_) * (n_ + 1) / 2; }
  // The current factor's pivots L_jj^2 (SparseCholesky::pivots).
  std::vector<double> pivots() const;

 private:
  int n_ = 0;
  int ld_ = 0;  // factor_'s leading dimension (kernels::dense_cholesky_padded_rows)
  std::vector<int> column_start_, row_index_;
  std::vector<double> factor_;  // A's lower triangle, then L (column-major, ld_ x n_)
  std::vector<float> single_factor_;  // L's lower triangle in float (n x n; upper unused)
  bool single_factor_current_ = false;  // single_factor_ holds the current factor
  void fill_lower(const std::vector<double>& values);  // factor_ = the lower triangle of A
};

}  // namespace dgtex::detail
