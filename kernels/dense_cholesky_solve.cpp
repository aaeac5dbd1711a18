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

template <class V, int L>
__attribute__((always_inline)) inline void solve(int n, const double* __restrict factor, double* __restrict x) {
  constexpr int NV = lanes / L;
  for (int j = 0; j < n; ++j) {
    const double* column = factor + static_cast<std::size_t>(j) * n;
    const double yj = x[j] / column[j];
    x[j] = yj;
    int i = j + 1;
    for (; i + L <= n; i += L) {
      V c, y;
      __builtin_memcpy(&c, column + i, sizeof(V));
      __builtin_memcpy(&y, x + i, sizeof(V));
      y = y - c * yj;
      __builtin_memcpy(x + i, &y, sizeof(V));
    }
    for (; i < n; ++i) x[i] = x[i] - column[i] * yj;
  }
  for (int j = n - 1; j >= 0; --j) {
    const double* below = factor + static_cast<std::size_t>(j) * n + j + 1;
    const double* xb = x + j + 1;
    const int count = n - j - 1;
    V acc[NV];
    for (int v = 0; v < NV; ++v) acc[v] = V{};
    int q = 0;
    for (; q + lanes <= count; q += lanes)
#pragma GCC unroll 8
      for (int v = 0; v < NV; ++v) {
        V c, y;
        __builtin_memcpy(&c, below + q + v * L, sizeof(V));
        __builtin_memcpy(&y, xb + q + v * L, sizeof(V));
        acc[v] = acc[v] + c * y;
      }
    double s[lanes];
    for (int v = 0; v < NV; ++v) __builtin_memcpy(s + v * L, &acc[v], sizeof(V));
    for (int l = 0; q < count; ++q, ++l) s[l] = s[l] + below[q] * xb[q];
    x[j] = (x[j] - halving_sum(s)) / factor[static_cast<std::size_t>(j) * n + j];
  }
}

__attribute__((target("avx512f"))) void solve_avx512(int n, const double* factor, double* x) {
  solve<V8, 8>(n, factor, x);
}
__attribute__((target("avx2"))) void solve_avx2(int n, const double* factor, double* x) { solve<V4, 4>(n, factor, x); }
void solve_baseline(int n, const double* factor, double* x) { solve<V2, 2>(n, factor, x); }

}  // namespace

void dense_cholesky_solve(int n, const double* L, double* x, VectorPath path) {
  kernel_of(path, solve_avx512, solve_avx2, solve_baseline)(n, L, x);
}

void dense_cholesky_solve_reference(int n, const double* L, double* x) {
  for (int j = 0; j < n; ++j) {
    const double* column = L + static_cast<std::size_t>(j) * n;
    x[j] = x[j] / column[j];
    for (int i = j + 1; i < n; ++i) x[i] = x[i] - column[i] * x[j];
  }
  for (int j = n - 1; j >= 0; --j) {
    const double* column = L + static_cast<std::size_t>(j) * n;
    double s[lanes] = {};
    for (int i = j + 1; i < n; ++i) {
      double& lane = s[(i - j - 1) % lanes];
      lane = lane + column[i] * x[i];
    }
    x[j] = (x[j] - halving_sum(s)) / column[j];
  }
}

}  // namespace dgtex::kernels
