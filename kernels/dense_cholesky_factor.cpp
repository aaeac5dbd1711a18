#include "dgtex/kernels/dense_cholesky_factor.h"

#include <cmath>
#include <cstddef>

namespace dgtex::kernels {
namespace {

typedef double V8 __attribute__((vector_size(64)));
typedef double V4 __attribute__((vector_size(32)));
typedef double V2 __attribute__((vector_size(16)));

constexpr int panel = 4;      // columns finished per pass over the columns to their left
constexpr int registers = 2;  // vectors of rows per pass (8 accumulators with 4 columns), then 1

bool usable_pivot(double s) { return s > 0 && std::isfinite(s); }

struct Matrix {
  double* a;
  int ld;
  double* column(int j) const { return a + static_cast<std::size_t>(j) * ld; }
};

// The products with the columns left of the panel, s_{i, j+c} = A_{i, j+c} - sum_{k<j}
// L_ik L_{j+c,k}, for R vectors of L rows from row i on, in registers.
template <class V, int L, int W, int R>
__attribute__((always_inline)) inline void left_products(Matrix m, int j, int i, V (&s)[W][R]) {
  for (int c = 0; c < W; ++c)
    for (int v = 0; v < R; ++v) __builtin_memcpy(&s[c][v], m.column(j + c) + i + v * L, sizeof(V));
  for (int k = 0; k < j; ++k) {
    const double* left = m.column(k);
    V lik[R];
    for (int v = 0; v < R; ++v) __builtin_memcpy(&lik[v], left + i + v * L, sizeof(V));
#pragma GCC unroll 4
    for (int c = 0; c < W; ++c) {
      const double ljk = left[j + c];
      for (int v = 0; v < R; ++v) s[c][v] = s[c][v] - lik[v] * ljk;
    }
  }
}

// The panel's own columns, in order, on the sums from left_products: then L_{i, j+c}.
template <class V, int W, int R>
__attribute__((always_inline)) inline void panel_products(Matrix m, int j, const double* pivots, V (&s)[W][R]) {
  for (int c = 0; c < W; ++c) {
    for (int p = 0; p < c; ++p) {
      const double ljp = m.column(j + p)[j + c];
      for (int v = 0; v < R; ++v) s[c][v] = s[c][v] - s[p][v] * ljp;  // s[p] holds L_{i, j+p} by now
    }
    for (int v = 0; v < R; ++v) s[c][v] = s[c][v] / pivots[c];
  }
}

template <class V, int L, int W, int R>
__attribute__((always_inline)) inline void store(Matrix m, int j, int i, const V (&s)[W][R]) {
  for (int c = 0; c < W; ++c)
    for (int v = 0; v < R; ++v) __builtin_memcpy(m.column(j + c) + i + v * L, &s[c][v], sizeof(V));
}

// The panel's diagonal block (its lower triangle) from the left products stored there, one
// entry at a time: this gives the pivots. Returns the column of an unusable pivot, or -1.
template <int W>
__attribute__((always_inline)) inline int diagonal_block(Matrix m, int j, double* pivots) {
  for (int c = 0; c < W; ++c) {
    for (int i = j + c; i < j + W; ++i) {
      double s = m.column(j + c)[i];
      for (int p = 0; p < c; ++p) s = s - m.column(j + p)[i] * m.column(j + p)[j + c];
      if (i == j + c) {
        if (!usable_pivot(s)) return j + c;
        pivots[c] = std::sqrt(s);
        m.column(j + c)[i] = pivots[c];
      } else {
        m.column(j + c)[i] = s / pivots[c];
      }
    }
  }
  return -1;
}

// Columns j..j+W-1. The first pass (from the aligned row at or above j) holds the diagonal
// block: its left products are stored, the block is finished one entry at a time, then the
// pass finishes its rows below the block. Every later pass runs in registers throughout.
// Rows above the diagonal and below n take part too (scratch: the strict upper triangle and
// the padding), so no pass needs a scalar remainder.
template <class V, int L, int W>
__attribute__((always_inline)) inline int factor_panel(Matrix m, int n, int j) {
  constexpr int rows = registers * L;
  const int first = j / L * L;
  V s[W][registers];
  left_products<V, L, W, registers>(m, j, first, s);
  store<V, L, W, registers>(m, j, first, s);
  double pivots[W];
  const int bad = diagonal_block<W>(m, j, pivots);
  if (bad >= 0) return bad;
  double block[W][W];  // the finished diagonal block, put back after the pass overwrote it
  for (int c = 0; c < W; ++c)
    for (int i = c; i < W; ++i) block[c][i] = m.column(j + c)[j + i];
  panel_products<V, W, registers>(m, j, pivots, s);
  store<V, L, W, registers>(m, j, first, s);
  for (int c = 0; c < W; ++c)
    for (int i = c; i < W; ++i) m.column(j + c)[j + i] = block[c][i];
  int i = first + rows;
  const int end = n + (L - n % L) % L;  // rows up to a whole vector past n (the padding)
  for (; i + rows <= end; i += rows) {
    left_products<V, L, W, registers>(m, j, i, s);
    panel_products<V, W, registers>(m, j, pivots, s);
    store<V, L, W, registers>(m, j, i, s);
  }
  if (i < end) {
    V t[W][1];
    left_products<V, L, W, 1>(m, j, i, t);
    panel_products<V, W, 1>(m, j, pivots, t);
    store<V, L, W, 1>(m, j, i, t);
  }
  return -1;
}

template <class V, int L>
__attribute__((always_inline)) inline int factor(int n, int ld, double* a) {
  const Matrix m{a, ld};
  int j = 0;
  for (; j + panel <= n; j += panel) {
    const int bad = factor_panel<V, L, panel>(m, n, j);
    if (bad >= 0) return bad;
  }
  switch (n - j) {
    case 3: return factor_panel<V, L, 3>(m, n, j);
    case 2: return factor_panel<V, L, 2>(m, n, j);
    case 1: return factor_panel<V, L, 1>(m, n, j);
    default: return -1;
  }
}

__attribute__((target("avx512f"))) int factor_avx512(int n, int ld, double* a) { return factor<V8, 8>(n, ld, a); }
__attribute__((target("avx2"))) int factor_avx2(int n, int ld, double* a) { return factor<V4, 4>(n, ld, a); }
int factor_baseline(int n, int ld, double* a) { return factor<V2, 2>(n, ld, a); }

}  // namespace

int dense_cholesky_padded_rows(int n) { return (n + 7) / 8 * 8 + 8; }

int dense_cholesky_factor(int n, int ld, double* A, VectorPath path) {
  return kernel_of(path, factor_avx512, factor_avx2, factor_baseline)(n, ld, A);
}

int dense_cholesky_factor_reference(int n, int ld, double* A) {
  const Matrix m{A, ld};
  for (int j = 0; j < n; ++j) {
    double pivot = 0;
    for (int i = j; i < n; ++i) {
      double s = m.column(j)[i];
      for (int k = 0; k < j; ++k) s = s - m.column(k)[i] * m.column(k)[j];
      if (i == j) {
        if (!usable_pivot(s)) return j;
        pivot = std::sqrt(s);
        m.column(j)[i] = pivot;
      } else {
        m.column(j)[i] = s / pivot;
      }
    }
  }
  return -1;
}

}  // namespace dgtex::kernels
