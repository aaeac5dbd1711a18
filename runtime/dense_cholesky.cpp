#include "dense_cholesky.h"

#include <cstddef>
#include <stdexcept>
#include <string>

#include "dgtex/kernels/dense_cholesky_factor.h"
#include "dgtex/kernels/dense_cholesky_solve.h"
#include "dgtex/sparse_cholesky.h"

namespace dgtex::detail {

void DenseCholesky::set_pattern(int n, const std::vector<int>& column_start, const std::vector<int>& row_index) {
  n_ = n;
  ld_ = kernels::dense_cholesky_padded_rows(n);
  column_start_ = column_start;
  row_index_ = row_index;
  single_factor_current_ = false;
}

void DenseCholesky::fill_lower(const std::vector<double>& values) {
  // Zeros elsewhere: the kernel's scratch (upper triangle, padding rows) must be finite.
  factor_.assign(static_cast<std::size_t>(ld_) * n_, 0.0);
  for (int j = 0; j < n_; ++j)
    for (int k = column_start_[j]; k < column_start_[j + 1]; ++k)
      factor_[static_cast<std::size_t>(j) * ld_ + row_index_[k]] = values[k];
}

void DenseCholesky::factorize(const std::vector<double>& values) {
  if (values.size() != row_index_.size())
    throw std::invalid_argument("SparseCholesky::factorize: value count does not match the pattern");
  single_factor_current_ = false;  // it belonged to the previous factor
  fill_lower(values);
  const int bad = kernels::dense_cholesky_factor(n_, ld_, factor_.data());
  if (bad >= 0)
    throw NotPositiveDefinite("matrix not positive definite (non-positive pivot at column " + std::to_string(bad) +
                                  " of " + std::to_string(n_) + ")",
                              bad);
}

std::vector<double> DenseCholesky::pivots() const {
  std::vector<double> out(n_);
  for (int j = 0; j < n_; ++j) {
    const double l = factor_[static_cast<std::size_t>(j) * ld_ + j];
    out[j] = l * l;
  }
  return out;
}

void DenseCholesky::solve(const std::vector<double>& b, std::vector<double>& x) const {
  x.assign(b.begin(), b.begin() + n_);
  kernels::dense_cholesky_solve(n_, ld_, factor_.data(), x.data());
}

void DenseCholesky::copy_factor_to_single_precision() {
  if (n_ < SparseCholesky::dense_single_precision_min_unknowns) return;
  single_factor_.resize(static_cast<std::size_t>(n_) * n_);  // allocated once, kept between factors
  for (int j = 0; j < n_; ++j)
    for (int i = j; i < n_; ++i)
      single_factor_[static_cast<std::size_t>(j) * n_ + i] =
          static_cast<float>(factor_[static_cast<std::size_t>(j) * ld_ + i]);
  single_factor_current_ = true;
}

void DenseCholesky::solve_single_precision(const std::vector<double>& b, std::vector<double>& x) const {
  if (!single_factor_current_) return solve(b, x);
  x.assign(b.begin(), b.begin() + n_);
  kernels::dense_cholesky_solve(n_, n_, single_factor_.data(), x.data());
}

}  // namespace dgtex::detail
