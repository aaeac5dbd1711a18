#include "banded_cholesky.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace dgtex::detail {

int BandedCholesky::bandwidth(const Eigen::SparseMatrix<double>& a) {
  int bw = 0;
  for (int c = 0; c < a.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, c); it; ++it)
      bw = std::max(bw, std::abs(static_cast<int>(it.row()) - c));
  return bw;
}

bool BandedCholesky::factorize(const Eigen::SparseMatrix<double>& a) {
  n_ = static_cast<int>(a.rows());
  bw_ = bandwidth(a);
  band_.assign(static_cast<std::size_t>(n_) * (bw_ + 1), 0.0);
  for (int c = 0; c < a.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, c); it; ++it)
      if (it.row() >= c) at(static_cast<int>(it.row()), c) = it.value();
  // Row by row (left-looking): L(i, j) = (A(i, j) - sum_k L(i, k) L(j, k)) / L(j, j).
  for (int i = 0; i < n_; ++i) {
    const int first = std::max(0, i - bw_);
    for (int j = first; j <= i; ++j) {
      double sum = at(i, j);
      for (int k = std::max(first, j - bw_); k < j; ++k) sum -= at(i, k) * at(j, k);
      if (j < i) {
        at(i, j) = sum / at(j, j);
      } else {
        if (!(sum > 0) || !std::isfinite(sum)) return false;
        at(i, i) = std::sqrt(sum);
      }
    }
  }
  return true;
}

void BandedCholesky::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  x = b;
  for (int i = 0; i < n_; ++i) {  // L y = b
    double sum = x[i];
    for (int k = std::max(0, i - bw_); k < i; ++k) sum -= at(i, k) * x[k];
    x[i] = sum / at(i, i);
  }
  for (int i = n_ - 1; i >= 0; --i) {  // L^T x = y
    double sum = x[i];
    for (int k = i + 1; k <= std::min(n_ - 1, i + bw_); ++k) sum -= at(k, i) * x[k];
    x[i] = sum / at(i, i);
  }
}

}  // namespace dgtex::detail
