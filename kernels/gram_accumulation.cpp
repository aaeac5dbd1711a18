#include "dgtex/kernels/gram_accumulation.h"

#include <immintrin.h>

#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>

namespace dgtex::kernels {
namespace {

typedef double V8 __attribute__((vector_size(64)));
typedef double V4 __attribute__((vector_size(32)));
typedef double V2 __attribute__((vector_size(16)));

// c += a b, each lane rounded once (a fused multiply-add); a is a vector or a scalar in
// every lane. The tiles and the references sum with it alike, so every path gives the same
// bits: the AVX-512 and AVX2 paths by the FMA instruction, the baseline x86-64 path (no FMA
// instruction) by the C library's fma per lane, correctly rounded in software where the
// CPU has no FMA. Fused, the tiles run up to 1.4x faster: they are bound by their multiplies
// and adds (examples/bench_scenes_history.md, sessions 57-58). Not always_inline (in the
// tile templates, which have no target, that does not compile): the compiler inlines each
// into its own path's function. The scalar forms broadcast by intrinsic: a generic
// fill (a loop, or a - V{}) became eight masked loads a vector in the weighted Grams.
__attribute__((target("avx512f"))) inline void add_product(V8& c, const V8& a, const V8& b) {
  c = _mm512_fmadd_pd(a, b, c);
}
__attribute__((target("avx512f"))) inline void add_product(V8& c, double a, const V8& b) {
  c = _mm512_fmadd_pd(_mm512_set1_pd(a), b, c);
}
__attribute__((target("avx2,fma"))) inline void add_product(V4& c, const V4& a, const V4& b) {
  c = _mm256_fmadd_pd(a, b, c);
}
__attribute__((target("avx2,fma"))) inline void add_product(V4& c, double a, const V4& b) {
  c = _mm256_fmadd_pd(_mm256_set1_pd(a), b, c);
}
inline void add_product(V2& c, const V2& a, const V2& b) {
  c[0] = __builtin_fma(a[0], b[0], c[0]);
  c[1] = __builtin_fma(a[1], b[1], c[1]);
}
inline void add_product(V2& c, double a, const V2& b) {
  c[0] = __builtin_fma(a, b[0], c[0]);
  c[1] = __builtin_fma(a, b[1], c[1]);
}

// One tile of G += A^T B: output rows i0..i0+TR, columns c0..c0+L NV; each entry is summed
// over the rows in order from 0, then stored or added. GCC vector extensions keep the
// accumulators in registers; lanes never mix.
template <class V, int L, int TR, int NV>
__attribute__((always_inline)) inline void product_tile(int rows, int cols, const double* __restrict A,
                                                        const double* __restrict B, double* __restrict G, int i0,
                                                        int c0, bool overwrite) {
  V acc[TR][NV];
  for (int r = 0; r < TR; ++r)
    for (int v = 0; v < NV; ++v) acc[r][v] = V{};
  for (int k = 0; k < rows; ++k) {
    const double* a_row = A + static_cast<std::size_t>(k) * cols;
    const double* b_row = B + static_cast<std::size_t>(k) * cols;
    V b[NV];
    for (int v = 0; v < NV; ++v) __builtin_memcpy(&b[v], b_row + c0 + v * L, sizeof(V));
    for (int r = 0; r < TR; ++r) {
      const double a = a_row[i0 + r];
      for (int v = 0; v < NV; ++v) add_product(acc[r][v], a, b[v]);
    }
  }
  for (int r = 0; r < TR; ++r) {
    double* out = G + static_cast<std::size_t>(i0 + r) * cols + c0;
    for (int v = 0; v < NV; ++v) {
      V x = acc[r][v];
      if (!overwrite) {
        V old;
        __builtin_memcpy(&old, out + v * L, sizeof(V));
        x = old + x;
      }
      __builtin_memcpy(out + v * L, &x, sizeof(V));
    }
  }
}

// G += A^T B by tiles of TR rows and L NV columns, the last columns of a row by tiles of L;
// upper: each row of tiles starts at its diagonal (TR x TR below it are scratch), so every
// upper entry is covered exactly once.
template <class V, int L, int TR, int NV>
__attribute__((always_inline)) inline void product_tiles(int rows, int cols, const double* A, const double* B,
                                                         double* G, bool overwrite, bool upper) {
  constexpr int TC = L * NV;
  static_assert(gram_column_multiple % L == 0 && gram_column_multiple % TR == 0 && TR % L == 0,
                "tiles divide the padding");
  for (int i0 = 0; i0 < cols; i0 += TR) {
    int c0 = upper ? i0 : 0;
    for (; c0 + TC <= cols; c0 += TC) product_tile<V, L, TR, NV>(rows, cols, A, B, G, i0, c0, overwrite);
    for (; c0 < cols; c0 += L) product_tile<V, L, TR, 1>(rows, cols, A, B, G, i0, c0, overwrite);
  }
}

__attribute__((target("avx512f"))) void product_avx512(int rows, int cols, const double* A, const double* B,
                                                       double* G, bool overwrite, bool upper) {
  product_tiles<V8, 8, 8, 2>(rows, cols, A, B, G, overwrite, upper);
}
__attribute__((target("avx2,fma"))) void product_avx2(int rows, int cols, const double* A, const double* B,
                                                      double* G, bool overwrite, bool upper) {
  product_tiles<V4, 4, 4, 2>(rows, cols, A, B, G, overwrite, upper);
}
void product_baseline(int rows, int cols, const double* A, const double* B, double* G, bool overwrite, bool upper) {
  product_tiles<V2, 2, 4, 2>(rows, cols, A, B, G, overwrite, upper);
}

// One tile of the weighted Gram sums (accumulate_weighted_grams): output rows i0..i0+TR,
// columns c0..c0+L NV, every sum k < K in registers.
template <class V, int L, int TR, int NV, int R, int K>
__attribute__((always_inline)) inline void weighted_gram_tile(int points, int cols, const double* __restrict A,
                                                              const double* __restrict weights, double* const* G,
                                                              const bool* overwrite, int i0, int c0) {
  V acc[K][TR][NV];
  for (int k = 0; k < K; ++k)
    for (int t = 0; t < TR; ++t)
      for (int v = 0; v < NV; ++v) acc[k][t][v] = V{};
  for (int p = 0; p < points; ++p) {
    const double* rows = A + static_cast<std::size_t>(p) * R * cols;
    // Loaded as registers: a memcpy loop here was left as stack copies (the AVX2 path ran at
    // a third of the speed of six products).
    V b[R][NV];
#pragma GCC unroll 8
    for (int r = 0; r < R; ++r)
#pragma GCC unroll 8
      for (int v = 0; v < NV; ++v)
        __builtin_memcpy(&b[r][v], rows + static_cast<std::size_t>(r) * cols + c0 + v * L, sizeof(V));
    const double* w = weights + static_cast<std::size_t>(p) * K;
#pragma GCC unroll 8
    for (int t = 0; t < TR; ++t)
#pragma GCC unroll 8
      for (int v = 0; v < NV; ++v) {
        // From 0, every row's product fused in (as in the reference).
        V product = V{};
#pragma GCC unroll 8
        for (int r = 0; r < R; ++r) add_product(product, rows[static_cast<std::size_t>(r) * cols + i0 + t], b[r][v]);
#pragma GCC unroll 8
        for (int k = 0; k < K; ++k) add_product(acc[k][t][v], w[k], product);
      }
  }
  for (int k = 0; k < K; ++k)
    for (int t = 0; t < TR; ++t)
      for (int v = 0; v < NV; ++v) {
        double* out = G[k] + static_cast<std::size_t>(i0 + t) * cols + c0 + v * L;
        V x = acc[k][t][v];
        if (!overwrite[k]) {
          V old;
          __builtin_memcpy(&old, out, sizeof(V));
          x = old + x;
        }
        __builtin_memcpy(out, &x, sizeof(V));
      }
}

// Upper entries by tiles of TR rows and L NV columns (the last of a row by L), each row of
// tiles from the L-aligned column at or left of its diagonal.
template <class V, int L, int TR, int NV, int R, int K>
__attribute__((always_inline)) inline void weighted_gram_tiles(int points, int cols, const double* A,
                                                               const double* weights, double* const* G,
                                                               const bool* overwrite) {
  static_assert(gram_column_multiple % L == 0 && gram_column_multiple % TR == 0, "tiles divide the padding");
  for (int i0 = 0; i0 < cols; i0 += TR) {
    int c0 = i0 / L * L;
    for (; c0 + L * NV <= cols; c0 += L * NV)
      weighted_gram_tile<V, L, TR, NV, R, K>(points, cols, A, weights, G, overwrite, i0, c0);
    for (; c0 < cols; c0 += L) weighted_gram_tile<V, L, TR, 1, R, K>(points, cols, A, weights, G, overwrite, i0, c0);
  }
}

// The frame split's bending sums: 3 rows a point, 6 weights; 6 x TR accumulators (TR = 4
// spilled registers on AVX-512 and was no faster than six products).
__attribute__((target("avx512f"))) void weighted_grams_avx512(int points, int cols, const double* A,
                                                              const double* weights, double* const* G,
                                                              const bool* overwrite) {
  weighted_gram_tiles<V8, 8, 2, 1, 3, 6>(points, cols, A, weights, G, overwrite);
}
__attribute__((target("avx2,fma"))) void weighted_grams_avx2(int points, int cols, const double* A,
                                                             const double* weights, double* const* G,
                                                             const bool* overwrite) {
  weighted_gram_tiles<V4, 4, 2, 1, 3, 6>(points, cols, A, weights, G, overwrite);
}
void weighted_grams_baseline(int points, int cols, const double* A, const double* weights, double* const* G,
                             const bool* overwrite) {
  weighted_gram_tiles<V2, 2, 2, 1, 3, 6>(points, cols, A, weights, G, overwrite);
}

// out[j] += (s * scales[j]) * g[j], the add fused: elementwise, so every path rounds alike.
template <class V, int L>
__attribute__((always_inline)) inline void scaled_row(int count, double s, const double* __restrict scales,
                                                      const double* __restrict g, double* __restrict out) {
  int j = 0;
  for (; j + L <= count; j += L) {
    V c, x, o;
    __builtin_memcpy(&c, scales + j, sizeof(V));
    __builtin_memcpy(&x, g + j, sizeof(V));
    __builtin_memcpy(&o, out + j, sizeof(V));
    const V scale = s * c;
    add_product(o, scale, x);
    __builtin_memcpy(out + j, &o, sizeof(V));
  }
  for (; j < count; ++j) out[j] = __builtin_fma(s * scales[j], g[j], out[j]);
}

__attribute__((target("avx512f"))) void scaled_row_avx512(int count, double s, const double* scales, const double* g,
                                                          double* out) {
  scaled_row<V8, 8>(count, s, scales, g, out);
}
__attribute__((target("avx2,fma"))) void scaled_row_avx2(int count, double s, const double* scales,
                                                         const double* g, double* out) {
  scaled_row<V4, 4>(count, s, scales, g, out);
}
void scaled_row_baseline(int count, double s, const double* scales, const double* g, double* out) {
  scaled_row<V2, 2>(count, s, scales, g, out);
}

// The sums' count check of accumulate_weighted_grams and its reference.
void require_weighted_gram_count(const char* kernel, int count) {
  if (count < 0 || count > max_weighted_grams)
    throw std::invalid_argument(std::string(kernel) + ": " + std::to_string(count) + " sums (at most " +
                                std::to_string(max_weighted_grams) + ")");
}

}  // namespace

void accumulate_product(int rows, int cols, const double* A, const double* B, double* G, bool overwrite,
                        bool upper, VectorPath path) {
  kernel_of(path, product_avx512, product_avx2, product_baseline)(rows, cols, A, B, G, overwrite, upper);
}

void accumulate_weighted_grams(int points, int rows_per_point, int cols, const double* A, const double* weights,
                               int count, double* const* G, const bool* overwrite, VectorPath path) {
  require_weighted_gram_count("accumulate_weighted_grams", count);
  if (rows_per_point != 3 || count != 6) {  // no tiled path: the same sums entry by entry
    accumulate_weighted_grams_reference(points, rows_per_point, cols, A, weights, count, G, overwrite);
    return;
  }
  kernel_of(path, weighted_grams_avx512, weighted_grams_avx2, weighted_grams_baseline)(points, cols, A, weights, G,
                                                                                      overwrite);
}

void accumulate_gram_upper(int rows, int cols, const double* A, double* G, bool overwrite, VectorPath path) {
  accumulate_product(rows, cols, A, A, G, overwrite, true, path);
}

void add_scaled_row(int count, double s, const double* scales, const double* g, double* out, VectorPath path) {
  kernel_of(path, scaled_row_avx512, scaled_row_avx2, scaled_row_baseline)(count, s, scales, g, out);
}

void accumulate_product_reference(int rows, int cols, const double* A, const double* B, double* G, bool overwrite,
                                  bool upper) {
  for (int i = 0; i < cols; ++i)
    for (int j = upper ? i : 0; j < cols; ++j) {
      double sum = 0;
      for (int k = 0; k < rows; ++k)
        sum = std::fma(A[static_cast<std::size_t>(k) * cols + i], B[static_cast<std::size_t>(k) * cols + j], sum);
      double& out = G[static_cast<std::size_t>(i) * cols + j];
      out = overwrite ? sum : out + sum;
    }
}

void accumulate_weighted_grams_reference(int points, int rows_per_point, int cols, const double* A,
                                         const double* weights, int count, double* const* G, const bool* overwrite) {
  require_weighted_gram_count("accumulate_weighted_grams_reference", count);
  for (int i = 0; i < cols; ++i)
    for (int j = i; j < cols; ++j) {
      double sum[max_weighted_grams] = {};
      for (int p = 0; p < points; ++p) {
        const double* rows = A + static_cast<std::size_t>(p) * rows_per_point * cols;
        double product = 0;
        for (int r = 0; r < rows_per_point; ++r)
          product = std::fma(rows[static_cast<std::size_t>(r) * cols + i], rows[static_cast<std::size_t>(r) * cols + j],
                             product);
        for (int k = 0; k < count; ++k)
          sum[k] = std::fma(weights[static_cast<std::size_t>(p) * count + k], product, sum[k]);
      }
      for (int k = 0; k < count; ++k) {
        double& out = G[k][static_cast<std::size_t>(i) * cols + j];
        out = overwrite[k] ? sum[k] : out + sum[k];
      }
    }
}

void accumulate_gram_upper_reference(int rows, int cols, const double* A, double* G, bool overwrite) {
  accumulate_product_reference(rows, cols, A, A, G, overwrite, true);
}

}  // namespace dgtex::kernels
