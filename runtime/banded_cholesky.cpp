#include "banded_cholesky.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace dgtex::detail {
namespace {

// The numeric loops, cloned for AVX-512, AVX2 and the baseline (picked once per process
// through an ifunc). Vector lanes are written out as chunks of 8 scalars, each with the same
// operations in the same order in every clone (no FMA contraction, see
// cmake/areas/laplace_multigrid.cmake), so the factor and the solutions are the same bits on
// every machine.
#define DGTEX_BAND_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))

// Loops run in whole chunks: the band's zero padding absorbs the overrun, so no loop has a
// remainder.
constexpr int chunk = BandedCholesky::chunk;

int round_up(int count) { return (count + chunk - 1) / chunk * chunk; }

// Right-looking: column j is scaled by its inverse pivot, then its outer product is
// subtracted from the next bw columns, each update a contiguous column segment (vectors).
// The left-looking form's inner loop was a dot product, one dependent multiply-add after
// another (spiral T = 256, 991 unknowns, bw 32: 310 -> ~80 us on one AVX-512 core).
DGTEX_BAND_CLONES bool factor_columns(double* lower, double* inverse_pivot, int n, int bw, int stride) {
  for (int j = 0; j < n; ++j) {
    double* l = lower + static_cast<std::size_t>(j) * stride;  // L(j + d, j) at l[d]
    if (!(l[0] > 0) || !std::isfinite(l[0])) return false;
    const double pivot = std::sqrt(l[0]), inverse = 1.0 / pivot;
    l[0] = pivot;
    inverse_pivot[j] = inverse;
    for (int d = 1; d <= round_up(bw); ++d) l[d] *= inverse;
    const int m = std::min(bw, n - 1 - j);
    for (int k = 1; k <= m; ++k) {
      const double lk = l[k];
      if (lk == 0) continue;  // columns across a hole of the domain
      // L(j + k + e, j + k) at target[e]; entries past the band are padding (stay zero).
      double* __restrict target = lower + static_cast<std::size_t>(j + k) * stride;
      const double* __restrict source = l + k;
      for (int c = 0; c < round_up(bw - k + 1); c += chunk)
        for (int v = 0; v < chunk; ++v) target[c + v] -= source[c + v] * lk;
    }
  }
  return true;
}

// L y = b by columns, then L^T x = y by the rows of L (rows: L(j, j - bw' + e) at e, bw' = bw
// rounded up), both as contiguous chunked axpys, x[i] -= L(i, j) x[j] for j ascending, then
// descending. x[0 .. n) holds b on entry, x on exit; it is padded by `stride` zeros on both
// sides. (Blocks of 8 rows, to spare each step's vector loads the scalar stored by the step
// before, were slower: 16 -> 24 us a solve at spiral T = 256.)
DGTEX_BAND_CLONES void substitute(const double* lower, const double* rows, const double* inverse_pivot, int n,
                                  int bw, int stride, double* x) {
  const int below = round_up(bw);
  for (int j = 0; j < n; ++j) {
    const double xj = x[j] * inverse_pivot[j];
    x[j] = xj;
    double* __restrict y = x + j + 1;
    const double* __restrict l = lower + static_cast<std::size_t>(j) * stride + 1;
    for (int c = 0; c < below; c += chunk)
      for (int v = 0; v < chunk; ++v) y[c + v] -= l[c + v] * xj;
  }
  for (int j = n - 1; j >= 0; --j) {
    const double xj = x[j] * inverse_pivot[j];
    x[j] = xj;
    double* __restrict y = x + j - below;
    const double* __restrict l = rows + static_cast<std::size_t>(j) * below;
    for (int c = 0; c < below; c += chunk)
      for (int v = 0; v < chunk; ++v) y[c + v] -= l[c + v] * xj;
  }
}

}  // namespace

int BandedCholesky::bandwidth(const Eigen::SparseMatrix<double>& a) {
  int bw = 0;
  for (int c = 0; c < a.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, c); it; ++it)
      bw = std::max(bw, std::abs(static_cast<int>(it.row()) - c));
  return bw;
}

void BandedCholesky::reset(int n, int bw) {
  n_ = n;
  bw_ = bw;
  // A column (bw + 1 entries) plus the overrun of its last chunk (< chunk entries): every
  // chunked read or update of column j stays in column j's zeros.
  stride_ = bw_ + chunk;
  lower_ = MultigridBuffer(static_cast<std::size_t>(n_) * stride_);
  inverse_pivot_ = MultigridBuffer(n_);
}

bool BandedCholesky::factorize() {
  if (!factor_columns(lower_.data(), inverse_pivot_.data(), n_, bw_, stride_)) return false;
  // Row j of L left of the diagonal, right-aligned: L(j, j - below + e) at e.
  const int below = round_up(bw_);
  rows_ = MultigridBuffer(static_cast<std::size_t>(n_) * below);
  for (int j = 0; j < n_; ++j)
    for (int d = 1; d <= std::min(bw_, n_ - 1 - j); ++d)
      rows_[static_cast<std::size_t>(j + d) * below + (below - d)] = lower_[static_cast<std::size_t>(j) * stride_ + d];
  return true;
}

bool BandedCholesky::factorize(const Eigen::SparseMatrix<double>& a) {
  reset(static_cast<int>(a.rows()), bandwidth(a));
  for (int c = 0; c < a.outerSize(); ++c)
    for (Eigen::SparseMatrix<double>::InnerIterator it(a, c); it; ++it)
      if (it.row() >= c) set_lower(static_cast<int>(it.row()), c, it.value());
  return factorize();
}

void BandedCholesky::solve(const Eigen::VectorXd& b, Eigen::VectorXd& x) const {
  std::vector<double> padded(static_cast<std::size_t>(n_) + 2 * stride_, 0.0);
  std::copy(b.data(), b.data() + n_, padded.begin() + stride_);
  if (n_ > 0)
    substitute(lower_.data(), rows_.data(), inverse_pivot_.data(), n_, bw_, stride_, padded.data() + stride_);
  x.resize(n_);
  std::copy(padded.begin() + stride_, padded.begin() + stride_ + n_, x.data());
}

}  // namespace dgtex::detail
