#include "dgtex/kernels/gram_accumulation.h"

#include <cstddef>

namespace dgtex::kernels {
namespace {

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
      for (int v = 0; v < NV; ++v) acc[r][v] += a * b[v];
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

typedef double V8 __attribute__((vector_size(64)));
typedef double V4 __attribute__((vector_size(32)));
typedef double V2 __attribute__((vector_size(16)));

__attribute__((target("avx512f"))) void product_avx512(int rows, int cols, const double* A, const double* B,
                                                       double* G, bool overwrite, bool upper) {
  product_tiles<V8, 8, 8, 2>(rows, cols, A, B, G, overwrite, upper);
}
__attribute__((target("avx2"))) void product_avx2(int rows, int cols, const double* A, const double* B, double* G,
                                                  bool overwrite, bool upper) {
  product_tiles<V4, 4, 4, 2>(rows, cols, A, B, G, overwrite, upper);
}
void product_baseline(int rows, int cols, const double* A, const double* B, double* G, bool overwrite, bool upper) {
  product_tiles<V2, 2, 4, 2>(rows, cols, A, B, G, overwrite, upper);
}

// out[j] += (s * scales[j]) * g[j]: elementwise, so every path rounds alike.
template <class V, int L>
__attribute__((always_inline)) inline void scaled_row(int count, double s, const double* __restrict scales,
                                                      const double* __restrict g, double* __restrict out) {
  int j = 0;
  for (; j + L <= count; j += L) {
    V c, x, o;
    __builtin_memcpy(&c, scales + j, sizeof(V));
    __builtin_memcpy(&x, g + j, sizeof(V));
    __builtin_memcpy(&o, out + j, sizeof(V));
    o = o + (s * c) * x;
    __builtin_memcpy(out + j, &o, sizeof(V));
  }
  for (; j < count; ++j) out[j] = out[j] + (s * scales[j]) * g[j];
}

__attribute__((target("avx512f"))) void scaled_row_avx512(int count, double s, const double* scales, const double* g,
                                                          double* out) {
  scaled_row<V8, 8>(count, s, scales, g, out);
}
__attribute__((target("avx2"))) void scaled_row_avx2(int count, double s, const double* scales, const double* g,
                                                     double* out) {
  scaled_row<V4, 4>(count, s, scales, g, out);
}
void scaled_row_baseline(int count, double s, const double* scales, const double* g, double* out) {
  scaled_row<V2, 2>(count, s, scales, g, out);
}

bool supported(GramPath path) {
  __builtin_cpu_init();
  switch (path) {
    case GramPath::avx512: return __builtin_cpu_supports("avx512f");
    case GramPath::avx2: return __builtin_cpu_supports("avx2");
    default: return true;
  }
}

}  // namespace

bool gram_path_supported(GramPath path) { return supported(path); }

void accumulate_product(int rows, int cols, const double* A, const double* B, double* G, bool overwrite,
                        bool upper, GramPath path) {
  using ProductKernel = void (*)(int, int, const double*, const double*, double*, bool, bool);
  const auto kernel_for = [](GramPath p) -> ProductKernel {
    if (p == GramPath::best) p = supported(GramPath::avx512) ? GramPath::avx512
                                 : supported(GramPath::avx2) ? GramPath::avx2
                                                             : GramPath::baseline;
    switch (p) {
      case GramPath::avx512: return product_avx512;
      case GramPath::avx2: return product_avx2;
      default: return product_baseline;
    }
  };
  static const ProductKernel best = kernel_for(GramPath::best);
  (path == GramPath::best ? best : kernel_for(path))(rows, cols, A, B, G, overwrite, upper);
}

void accumulate_gram_upper(int rows, int cols, const double* A, double* G, bool overwrite, GramPath path) {
  accumulate_product(rows, cols, A, A, G, overwrite, true, path);
}

void add_scaled_row(int count, double s, const double* scales, const double* g, double* out) {
  using RowKernel = void (*)(int, double, const double*, const double*, double*);
  static const RowKernel kernel = supported(GramPath::avx512) ? scaled_row_avx512
                                  : supported(GramPath::avx2) ? scaled_row_avx2
                                                              : scaled_row_baseline;
  kernel(count, s, scales, g, out);
}

void accumulate_product_reference(int rows, int cols, const double* A, const double* B, double* G, bool overwrite,
                                  bool upper) {
  for (int i = 0; i < cols; ++i)
    for (int j = upper ? i : 0; j < cols; ++j) {
      double sum = 0;
      for (int k = 0; k < rows; ++k)
        sum += A[static_cast<std::size_t>(k) * cols + i] * B[static_cast<std::size_t>(k) * cols + j];
      double& out = G[static_cast<std::size_t>(i) * cols + j];
      out = overwrite ? sum : out + sum;
    }
}

void accumulate_gram_upper_reference(int rows, int cols, const double* A, double* G, bool overwrite) {
  accumulate_product_reference(rows, cols, A, A, G, overwrite, true);
}

}  // namespace dgtex::kernels
