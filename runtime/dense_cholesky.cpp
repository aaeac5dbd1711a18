#include "dense_cholesky.h"

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>

#include "cholmod_lock.h"
#include "dgtex/kernels/dense_cholesky_solve.h"
#include "dgtex/sparse_cholesky.h"

extern "C" {
// LAPACK's Cholesky factorisation (the trailing argument: the hidden length of uplo).
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info, std::size_t uplo_length);
}

namespace dgtex::detail {

void DenseCholesky::set_pattern(int n, const std::vector<int>& column_start, const std::vector<int>& row_index) {
  n_ = n;
  column_start_ = column_start;
  row_index_ = row_index;
  single_factor_current_ = false;
}

namespace {

// Below this size Eigen's LLT stays: in isolation dpotrf is as fast or faster there too
// (examples/bench_dense_cholesky), but inside the scenes it was slower (spiral1, n = 36-48:
// its factorisations 3.9-5.1 -> 5.2-8.6 ms over the run; chad, n <= 126: 5.4-5.6 -> 6.4-6.9).
constexpr int lapack_min_unknowns = 128;

}  // namespace

void DenseCholesky::fill_lower(const std::vector<double>& values) {
  factor_.setZero(n_, n_);
  for (int j = 0; j < n_; ++j)
    for (int k = column_start_[j]; k < column_start_[j + 1]; ++k) factor_(row_index_[k], j) = values[k];
}

void DenseCholesky::factorize(const std::vector<double>& values) {
  if (values.size() != row_index_.size())
    throw std::invalid_argument("SparseCholesky::factorize: value count does not match the pattern");
  single_factor_current_ = false;  // it belonged to the previous factor
  fill_lower(values);
  int bad = -1;
  if (n_ >= lapack_min_unknowns) {
    // LAPACK (OpenBLAS, serial): 1.5-1.9x Eigen's LLT at n = 168-498 in this baseline
    // x86-64 build. info > 0 names the first leading minor that is not positive definite (a
    // non-positive or NaN pivot).
    int info = 0;
    {
      const auto lock = lock_cholmod();  // the BLAS is not safe for concurrent calls (cholmod_lock.h)
      dpotrf_("L", &n_, factor_.data(), &n_, &info, 1);
    }
    if (info < 0) throw std::logic_error("dpotrf: argument " + std::to_string(-info) + " is invalid");
    if (info > 0) bad = info - 1;
    // OpenBLAS's own dpotrf tests pivots with <= 0 only: a NaN pivot passes as NaN.
    for (int j = 0; bad < 0 && j < n_; ++j)
      if (!std::isfinite(factor_(j, j))) bad = j;
  } else {
    Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>, Eigen::Lower> in_place(factor_);
    if (in_place.info() != Eigen::Success || !factor_.diagonal().allFinite()) {
      // Eigen does not say where it stopped: an unblocked left-looking pass over the lower
      // triangle finds the first non-positive (or NaN) pivot.
      fill_lower(values);
      Eigen::MatrixXd& a = factor_;
      for (int j = 0; j < n_ && bad < 0; ++j) {
        for (int k = 0; k < j; ++k) a.col(j).tail(n_ - j) -= a(j, k) * a.col(k).tail(n_ - j);
        if (!(a(j, j) > 0) || !std::isfinite(a(j, j))) {
          bad = j;
          break;
        }
        a(j, j) = std::sqrt(a(j, j));
        a.col(j).tail(n_ - j - 1) /= a(j, j);
      }
      if (bad < 0) bad = 0;  // Eigen failed where the plain pass did not: report the start
    }
  }
  if (bad >= 0)
    throw NotPositiveDefinite("matrix not positive definite (non-positive pivot at column " + std::to_string(bad) +
                                  " of " + std::to_string(n_) + ")",
                              bad);
}

void DenseCholesky::solve(const std::vector<double>& b, std::vector<double>& x) const {
  x.assign(b.begin(), b.begin() + n_);
  kernels::dense_cholesky_solve(n_, factor_.data(), x.data());
}

void DenseCholesky::copy_factor_to_single_precision() {
  if (n_ < SparseCholesky::dense_single_precision_min_unknowns) return;
  single_factor_.resize(static_cast<std::size_t>(n_) * n_);  // allocated once, kept between factors
  for (int j = 0; j < n_; ++j)
    for (int i = j; i < n_; ++i)
      single_factor_[static_cast<std::size_t>(j) * n_ + i] = static_cast<float>(factor_(i, j));
  single_factor_current_ = true;
}

void DenseCholesky::solve_single_precision(const std::vector<double>& b, std::vector<double>& x) const {
  if (!single_factor_current_) return solve(b, x);
  x.assign(b.begin(), b.begin() + n_);
  kernels::dense_cholesky_solve(n_, single_factor_.data(), x.data());
}

}  // namespace dgtex::detail
