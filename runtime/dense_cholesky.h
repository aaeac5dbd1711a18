#pragma once
// Internal to SparseCholesky: the dense factorisation it uses for small systems (a cut
// single element has 39-450 unknowns, mostly coupled to each other). CHOLMOD's analysis,
// supernodal bookkeeping and OpenMP regions cost more there than the arithmetic: n = 39,
// analysis + factorisation 0.03-0.12 ms against 0.007 ms for Eigen's blocked LLT, and 0.2-2
// ms inside a scene step with spinning OpenMP threads; n = 441 (fully dense) 2.9-3.4 ms
// against 2.2 ms (one run of each, 2-core machine). Since session 18 systems of 128 unknowns
// and more are factorised by LAPACK's dpotrf (OpenBLAS, serial; under the process-wide BLAS
// lock, cholmod_lock.h): 1.5x Eigen's LLT at n = 168 and 1.8-1.9x at 441-498 in this
// baseline x86-64 build (examples/bench_dense_cholesky). The solves are
// kernels::dense_cholesky_solve (a path per instruction set): Eigen's triangular solves
// took half the time of dpotrs, and these 3/4 of Eigen's (the accordion's preconditioner,
// 447 unknowns, 60 -> 45 us an application in its scene).
#include <vector>

#include <Eigen/Dense>

namespace dgtex::detail {

class DenseCholesky {
 public:
  // The lower-triangle compressed-column pattern whose values factorize() receives.
  void set_pattern(int n, const std::vector<int>& column_start, const std::vector<int>& row_index);
  // Throws NotPositiveDefinite (column in the matrix's own order) for a non-positive or
  // non-finite pivot.
  void factorize(const std::vector<double>& values);
  void solve(const std::vector<double>& b, std::vector<double>& x) const;
  std::int64_t factor_nonzeros() const { return static_cast<std::int64_t>(n_) * (n_ + 1) / 2; }

 private:
  int n_ = 0;
  std::vector<int> column_start_, row_index_;
  Eigen::MatrixXd factor_;  // the lower triangle of A, then its Cholesky factor L
  void fill_lower(const std::vector<double>& values);  // factor_ = the lower triangle of A
};

}  // namespace dgtex::detail
