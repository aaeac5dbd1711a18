#include "dense_cholesky.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "dgtex/sparse_cholesky.h"

namespace dgtex::detail {

void DenseCholesky::set_pattern(int n, const std::vector<int>& column_start, const std::vector<int>& row_index) {
  n_ = n;
  column_start_ = column_start;
  row_index_ = row_index;
}

void DenseCholesky::factorize(const std::vector<double>& values) {
  if (values.size() != row_index_.size())
    throw std::invalid_argument("SparseCholesky::factorize: value count does not match the pattern");
  matrix_.setZero(n_, n_);
  for (int j = 0; j < n_; ++j)
    for (int k = column_start_[j]; k < column_start_[j + 1]; ++k) matrix_(row_index_[k], j) = values[k];
  factor_.compute(matrix_);
  const auto& L = factor_.matrixLLT();
  int bad = -1;
  if (factor_.info() != Eigen::Success || !L.diagonal().allFinite()) {
    // Eigen does not say where it stopped: an unblocked left-looking pass over the lower
    // triangle finds the first non-positive (or NaN) pivot.
    Eigen::MatrixXd& a = matrix_;
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
  if (bad >= 0)
    throw NotPositiveDefinite("matrix not positive definite (non-positive pivot at column " + std::to_string(bad) +
                                  " of " + std::to_string(n_) + ")",
                              bad);
}

void DenseCholesky::solve(const std::vector<double>& b, std::vector<double>& x) const {
  x.resize(n_);
  Eigen::Map<Eigen::VectorXd>(x.data(), n_) = factor_.solve(Eigen::Map<const Eigen::VectorXd>(b.data(), n_));
}

}  // namespace dgtex::detail
