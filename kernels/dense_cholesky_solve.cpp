#include "dgtex/kernels/dense_cholesky_solve.h"

#include <cstddef>

namespace dgtex::kernels {
namespace {

typedef double V8 __attribute__((vector_size(64)));
typedef double V4 __attribute__((vector_size(32)));
typedef double V2 __attribute__((vector_size(16)));

constexpr int lanes = 8;  // of the backward sums

// The sum of the 8 lanes: l + 4, then l + 2, l + 1.
double halving_sum(double* s) {
  for (int width = lanes / 2; width >= 1; width /= 2)
    for (int l = 0; l < width; ++l) s[l] = s[l] + s[l + width];
  return s[0];
}

// Loads L lanes of the factor as doubles: a float factor is widened exactly, so a float
// factor changes only the rounding of L itself, never the order of the operations.
// (Written to a reference: a vector return value would change the ABI between paths.)
template <int L, class V, class Scalar>
__attribute__((always_inline)) inline void load_lanes(V& v, const Scalar* p) {
  if constexpr (sizeof(Scalar) == sizeof(double)) {
    __builtin_memcpy(&v, p, sizeof(V));
  } else {
    typedef float F __attribute__((vector_size(L * sizeof(float))));
    F f;
    __builtin_memcpy(&f, p, sizeof(F));
    v = __builtin_convertvector(f, V);
  }
}

constexpr int block = 8;  // columns of the forward sweep applied per pass over x
// From this size on the sweeps prefetch the columns they read next. Such a factor (256 KB
// and more as float) has left the L2 cache by the next application in a scene (the K
// product between them reads 1.6 MB for the accordion), and each column is a short run the
// hardware prefetcher barely ramps up on: the accordion's solve per step, 5 runs of each,
// 0.336-0.383 -> 0.314-0.362 ms. Below it the factor stays in L2, and the prefetches only
// cost instructions (n = 168 in isolation: 6.4 -> 6.9 us).
constexpr int prefetch_min_unknowns = 256;

// Prefetches `count` entries from p on.
template <class Scalar>
__attribute__((always_inline)) inline void prefetch_entries(const Scalar* p, int count) {
  const char* bytes = reinterpret_cast<const char*>(p);
  for (int b = 0; b < static_cast<int>(count * sizeof(Scalar)); b += 64) __builtin_prefetch(bytes + b);
}

template <class V, int L, class Scalar>
__attribute__((always_inline)) inline void solve(int n, int ld, const Scalar* __restrict factor, double* __restrict x) {
  constexpr int NV = lanes / L;
  const bool prefetch = n >= prefetch_min_unknowns;
  // Forward, in blocks of 8 columns: the block's triangle first, then each entry below it
  // takes the 8 columns' updates in column order, loaded and stored once instead of 8
  // times. Every entry sees the same operations in the same order as column by column.
  int j = 0;
  for (; j + block <= n; j += block) {
    const Scalar* column[block];
    double y[block];
    for (int k = 0; k < block; ++k) {
      column[k] = factor + static_cast<std::size_t>(j + k) * ld;
      y[k] = x[j + k] / static_cast<double>(column[k][j + k]);
      x[j + k] = y[k];
      for (int i = j + k + 1; i < j + block; ++i) x[i] = x[i] - static_cast<double>(column[k][i]) * y[k];
    }
    if (prefetch && j + 2 * block <= n)  // the next block's columns, from its first row on
      for (int k = 0; k < block; ++k)
        prefetch_entries(column[k] + static_cast<std::size_t>(block) * ld + j + block, n - j - block);
    int i = j + block;
    for (; i + L <= n; i += L) {
      V xi;
      __builtin_memcpy(&xi, x + i, sizeof(V));
#pragma GCC unroll 8
      for (int k = 0; k < block; ++k) {
        V c;
        load_lanes<L>(c, column[k] + i);
        xi = xi - c * y[k];
      }
      __builtin_memcpy(x + i, &xi, sizeof(V));
    }
    for (; i < n; ++i)
      for (int k = 0; k < block; ++k) x[i] = x[i] - static_cast<double>(column[k][i]) * y[k];
  }
  for (; j < n; ++j) {
    const Scalar* column = factor + static_cast<std::size_t>(j) * ld;
    const double yj = x[j] / static_cast<double>(column[j]);
    x[j] = yj;
    for (int i = j + 1; i < n; ++i) x[i] = x[i] - static_cast<double>(column[i]) * yj;
  }
  for (int j = n - 1; j >= 0; --j) {
    const Scalar* below = factor + static_cast<std::size_t>(j) * ld + j + 1;
    const double* xb = x + j + 1;
    const int count = n - j - 1;
    if (prefetch && j > 0) prefetch_entries(below - ld - 1, count + 1);  // column j - 1 below its diagonal
    V acc[NV];
    for (int v = 0; v < NV; ++v) acc[v] = V{};
    int q = 0;
    for (; q + lanes <= count; q += lanes)
#pragma GCC unroll 8
      for (int v = 0; v < NV; ++v) {
        V c, y;
        load_lanes<L>(c, below + q + v * L);
        __builtin_memcpy(&y, xb + q + v * L, sizeof(V));
        acc[v] = acc[v] + c * y;
      }
    double s[lanes];
    for (int v = 0; v < NV; ++v) __builtin_memcpy(s + v * L, &acc[v], sizeof(V));
    for (int l = 0; q < count; ++q, ++l) s[l] = s[l] + static_cast<double>(below[q]) * xb[q];
    x[j] = (x[j] - halving_sum(s)) / static_cast<double>(factor[static_cast<std::size_t>(j) * ld + j]);
  }
}

template <class Scalar>
__attribute__((target("avx512f"))) void solve_avx512(int n, int ld, const Scalar* factor, double* x) {
  solve<V8, 8>(n, ld, factor, x);
}
template <class Scalar>
__attribute__((target("avx2"))) void solve_avx2(int n, int ld, const Scalar* factor, double* x) {
  solve<V4, 4>(n, ld, factor, x);
}
template <class Scalar>
void solve_baseline(int n, int ld, const Scalar* factor, double* x) {
  solve<V2, 2>(n, ld, factor, x);
}

template <class Scalar>
void solve_reference(int n, int ld, const Scalar* L, double* x) {
  for (int j = 0; j < n; ++j) {
    const Scalar* column = L + static_cast<std::size_t>(j) * ld;
    x[j] = x[j] / static_cast<double>(column[j]);
    for (int i = j + 1; i < n; ++i) x[i] = x[i] - static_cast<double>(column[i]) * x[j];
  }
  for (int j = n - 1; j >= 0; --j) {
    const Scalar* column = L + static_cast<std::size_t>(j) * ld;
    double s[lanes] = {};
    for (int i = j + 1; i < n; ++i) {
      double& lane = s[(i - j - 1) % lanes];
      lane = lane + static_cast<double>(column[i]) * x[i];
    }
    x[j] = (x[j] - halving_sum(s)) / static_cast<double>(column[j]);
  }
}

}  // namespace

void dense_cholesky_solve(int n, int ld, const double* L, double* x, VectorPath path) {
  kernel_of(path, solve_avx512<double>, solve_avx2<double>, solve_baseline<double>)(n, ld, L, x);
}

void dense_cholesky_solve(int n, int ld, const float* L, double* x, VectorPath path) {
  kernel_of(path, solve_avx512<float>, solve_avx2<float>, solve_baseline<float>)(n, ld, L, x);
}

void dense_cholesky_solve_reference(int n, int ld, const double* L, double* x) { solve_reference(n, ld, L, x); }
void dense_cholesky_solve_reference(int n, int ld, const float* L, double* x) { solve_reference(n, ld, L, x); }

}  // namespace dgtex::kernels
