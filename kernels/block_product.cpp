#include "dgtex/kernels/block_product.h"

#include <cstddef>

namespace dgtex::kernels {
namespace {

typedef double V8 __attribute__((vector_size(64)));
typedef double V4 __attribute__((vector_size(32)));
typedef double V2 __attribute__((vector_size(16)));

constexpr int streams = 4;  // independent sums a row (hide the add latency)

// Entries 0..7 of a block as 8 / L vectors of L lanes, entry 8 as a scalar; NX vectors.
// Scalar blocks (with NX = 1): entries 0..2 in the first lanes, at least 4.
template <class V, int L, int NX>
struct RowSums {
  static constexpr int vectors = 8 / L;
  static constexpr int scalar_vectors = L >= 4 ? 1 : 4 / L;
  V lanes[NX][streams][vectors];
  double last[NX][streams];
  V scalar_lanes[streams][scalar_vectors];
};

// Adds block `b` (node column offset c9 in the spread vectors) to stream U, and with
// Scalars the scalar block m I (same x: the first lanes of its spread node).
template <int U, bool Scalars, class V, int L, int NX>
__attribute__((always_inline)) inline void add_block(const double* __restrict b, double m,
                                                     const double* const* spread, std::int64_t c9,
                                                     RowSums<V, L, NX>& sums) {
  constexpr int NV = RowSums<V, L, NX>::vectors;
  V block[NV];
#pragma GCC unroll 4
  for (int v = 0; v < NV; ++v) __builtin_memcpy(&block[v], b + v * L, sizeof(V));
#pragma GCC unroll 2
  for (int x = 0; x < NX; ++x) {
    const double* s = spread[x] + c9;
    V xs[NV];
#pragma GCC unroll 4
    for (int v = 0; v < NV; ++v) {
      __builtin_memcpy(&xs[v], s + v * L, sizeof(V));
      sums.lanes[x][U][v] = sums.lanes[x][U][v] + block[v] * xs[v];
    }
    sums.last[x][U] = sums.last[x][U] + b[8] * s[8];
    if constexpr (Scalars) {
#pragma GCC unroll 4
      for (int v = 0; v < RowSums<V, L, NX>::scalar_vectors; ++v)
        sums.scalar_lanes[U][v] = sums.scalar_lanes[U][v] + m * xs[v];
    }
  }
}

// Rows of K x (NX vectors), with Scalars also of S x (NX = 1, S given by its scalars).
template <bool Scalars, class V, int L, int NX>
__attribute__((always_inline)) inline void block_rows(BlockRows rows, std::int64_t first, std::int64_t last,
                                                      const double* __restrict blocks,
                                                      const double* __restrict scalars, const double* const* spread,
                                                      double* const* y, double* y_scalars) {
  static_assert(!Scalars || NX == 1, "scalar blocks with one vector");
  using Sums = RowSums<V, L, NX>;
  constexpr int NV = Sums::vectors, NS = Sums::scalar_vectors;
  for (std::int64_t r = first; r < last; ++r) {
    Sums sums;
    for (int u = 0; u < streams; ++u) {
      for (int x = 0; x < NX; ++x) {
        for (int v = 0; v < NV; ++v) sums.lanes[x][u][v] = V{};
        sums.last[x][u] = 0.0;
      }
      for (int v = 0; v < NS; ++v) sums.scalar_lanes[u][v] = V{};
    }
    const std::int64_t begin = rows.row_start[r], end = rows.row_start[r + 1];
    const auto block = [&](std::int64_t k) { return blocks + 9 * k; };
    const auto scalar = [&](std::int64_t k) { return Scalars ? scalars[k] : 0.0; };
    const auto c9 = [&](std::int64_t k) { return 9 * static_cast<std::int64_t>(rows.column[k]); };
    std::int64_t k = begin;
    for (; k + streams <= end; k += streams) {
      add_block<0, Scalars>(block(k), scalar(k), spread, c9(k), sums);
      add_block<1, Scalars>(block(k + 1), scalar(k + 1), spread, c9(k + 1), sums);
      add_block<2, Scalars>(block(k + 2), scalar(k + 2), spread, c9(k + 2), sums);
      add_block<3, Scalars>(block(k + 3), scalar(k + 3), spread, c9(k + 3), sums);
    }
    if (k < end) add_block<0, Scalars>(block(k), scalar(k), spread, c9(k), sums);
    if (k + 1 < end) add_block<1, Scalars>(block(k + 1), scalar(k + 1), spread, c9(k + 1), sums);
    if (k + 2 < end) add_block<2, Scalars>(block(k + 2), scalar(k + 2), spread, c9(k + 2), sums);
    for (int x = 0; x < NX; ++x) {
      double t[9];
      for (int v = 0; v < NV; ++v) {
        const V sum = (sums.lanes[x][0][v] + sums.lanes[x][1][v]) + (sums.lanes[x][2][v] + sums.lanes[x][3][v]);
        __builtin_memcpy(t + v * L, &sum, sizeof(V));
      }
      t[8] = (sums.last[x][0] + sums.last[x][1]) + (sums.last[x][2] + sums.last[x][3]);
      for (int i = 0; i < 3; ++i) y[x][3 * r + i] = (t[3 * i] + t[3 * i + 1]) + t[3 * i + 2];
    }
    if constexpr (Scalars) {
      double t[NS * L];
      for (int v = 0; v < NS; ++v) {
        const V sum = (sums.scalar_lanes[0][v] + sums.scalar_lanes[1][v]) +
                      (sums.scalar_lanes[2][v] + sums.scalar_lanes[3][v]);
        __builtin_memcpy(t + v * L, &sum, sizeof(V));
      }
      for (int i = 0; i < 3; ++i) y_scalars[3 * r + i] = t[i];
    }
  }
}

// Scalar blocks: entries 0..2 of the spread node in the first lanes (at least 4).
template <class V, int L>
__attribute__((always_inline)) inline void scalar_rows(BlockRows rows, std::int64_t first, std::int64_t last,
                                                       const double* __restrict scalars, const double* spread,
                                                       double* y) {
  constexpr int NV = L >= 4 ? 1 : 4 / L;
  for (std::int64_t r = first; r < last; ++r) {
    V lanes[streams][NV];
    for (int u = 0; u < streams; ++u)
      for (int v = 0; v < NV; ++v) lanes[u][v] = V{};
    const auto add = [&](int u, std::int64_t k) {
      const double* s = spread + 9 * static_cast<std::int64_t>(rows.column[k]);
      for (int v = 0; v < NV; ++v) {
        V xs;
        __builtin_memcpy(&xs, s + v * L, sizeof(V));
        lanes[u][v] = lanes[u][v] + scalars[k] * xs;
      }
    };
    const std::int64_t begin = rows.row_start[r], end = rows.row_start[r + 1];
    std::int64_t k = begin;
    for (; k + streams <= end; k += streams) {
      add(0, k);
      add(1, k + 1);
      add(2, k + 2);
      add(3, k + 3);
    }
    if (k < end) add(0, k);
    if (k + 1 < end) add(1, k + 1);
    if (k + 2 < end) add(2, k + 2);
    double t[NV * L];
    for (int v = 0; v < NV; ++v) {
      const V sum = (lanes[0][v] + lanes[1][v]) + (lanes[2][v] + lanes[3][v]);
      __builtin_memcpy(t + v * L, &sum, sizeof(V));
    }
    for (int i = 0; i < 3; ++i) y[3 * r + i] = t[i];
  }
}

// count: 1 or 2 vectors; scalars (with one vector) non-null: also y_scalars = S x.
using BlockRowsKernel = void (*)(BlockRows, std::int64_t, std::int64_t, const double*, const double*,
                                 const double* const*, double* const*, double*, int);
using ScalarRowsKernel = void (*)(BlockRows, std::int64_t, std::int64_t, const double*, const double*, double*);

#define DGTEX_BLOCK_ROWS_PATH(attribute, name, V, L)                                                              \
  attribute void block_rows_##name(BlockRows rows, std::int64_t first, std::int64_t last, const double* blocks,   \
                                   const double* scalars, const double* const* spread, double* const* y,          \
                                   double* y_scalars, int count) {                                                \
    if (count == 2) block_rows<false, V, L, 2>(rows, first, last, blocks, nullptr, spread, y, nullptr);           \
    else if (scalars) block_rows<true, V, L, 1>(rows, first, last, blocks, scalars, spread, y, y_scalars);        \
    else block_rows<false, V, L, 1>(rows, first, last, blocks, nullptr, spread, y, nullptr);                      \
  }                                                                                                               \
  attribute void scalar_rows_##name(BlockRows rows, std::int64_t first, std::int64_t last,                       \
                                    const double* scalars, const double* spread, double* y) {                    \
    scalar_rows<V, L>(rows, first, last, scalars, spread, y);                                                     \
  }
DGTEX_BLOCK_ROWS_PATH(__attribute__((target("avx512f"))), avx512, V8, 8)
DGTEX_BLOCK_ROWS_PATH(__attribute__((target("avx2"))), avx2, V4, 4)
DGTEX_BLOCK_ROWS_PATH(, baseline, V2, 2)
#undef DGTEX_BLOCK_ROWS_PATH

void block_rows_of(VectorPath path, BlockRows rows, std::int64_t first, std::int64_t last, const double* blocks,
                   const double* scalars, const double* const* spread, double* const* y, double* y_scalars,
                   int count) {
  static const BlockRowsKernel best = kernel_of(VectorPath::best, block_rows_avx512, block_rows_avx2, block_rows_baseline);
  const BlockRowsKernel kernel =
      path == VectorPath::best ? best : kernel_of(path, block_rows_avx512, block_rows_avx2, block_rows_baseline);
  kernel(rows, first, last, blocks, scalars, spread, y, y_scalars, count);
}

}  // namespace

void spread_block_vector(std::int64_t nodes, const double* x, double* spread) {
  for (std::int64_t c = 0; c < nodes; ++c)
    for (int m = 0; m < 9; ++m) spread[9 * c + m] = x[3 * c + m % 3];
}

void block_rows_product(BlockRows rows, std::int64_t first, std::int64_t last, const double* blocks,
                        const double* spread, double* y, VectorPath path) {
  block_rows_of(path, rows, first, last, blocks, nullptr, &spread, &y, nullptr, 1);
}

void block_and_scalar_rows_product(BlockRows rows, std::int64_t first, std::int64_t last, const double* blocks,
                                   const double* scalars, const double* spread, double* y, double* y_scalars,
                                   VectorPath path) {
  block_rows_of(path, rows, first, last, blocks, scalars, &spread, &y, y_scalars, 1);
}

void block_rows_product_pair(BlockRows rows, std::int64_t first, std::int64_t last, const double* blocks,
                             const double* spread1, const double* spread2, double* y1, double* y2, VectorPath path) {
  const double* spread[2] = {spread1, spread2};
  double* y[2] = {y1, y2};
  block_rows_of(path, rows, first, last, blocks, nullptr, spread, y, nullptr, 2);
}

void scalar_rows_product(BlockRows rows, std::int64_t first, std::int64_t last, const double* scalars,
                         const double* spread, double* y, VectorPath path) {
  static const ScalarRowsKernel best =
      kernel_of(VectorPath::best, scalar_rows_avx512, scalar_rows_avx2, scalar_rows_baseline);
  const ScalarRowsKernel kernel =
      path == VectorPath::best ? best : kernel_of(path, scalar_rows_avx512, scalar_rows_avx2, scalar_rows_baseline);
  kernel(rows, first, last, scalars, spread, y);
}

void block_rows_product_reference(BlockRows rows, std::int64_t first, std::int64_t last, const double* blocks,
                                  const double* x, double* y) {
  for (std::int64_t r = first; r < last; ++r) {
    double s[streams][9] = {};
    const std::int64_t begin = rows.row_start[r];
    for (std::int64_t k = begin; k < rows.row_start[r + 1]; ++k) {
      const double* b = blocks + 9 * k;
      const double* xc = x + 3 * static_cast<std::int64_t>(rows.column[k]);
      double* stream = s[(k - begin) % streams];
      for (int m = 0; m < 9; ++m) stream[m] = stream[m] + b[m] * xc[m % 3];
    }
    double t[9];
    for (int m = 0; m < 9; ++m) t[m] = (s[0][m] + s[1][m]) + (s[2][m] + s[3][m]);
    for (int i = 0; i < 3; ++i) y[3 * r + i] = (t[3 * i] + t[3 * i + 1]) + t[3 * i + 2];
  }
}

void scalar_rows_product_reference(BlockRows rows, std::int64_t first, std::int64_t last, const double* scalars,
                                   const double* x, double* y) {
  for (std::int64_t r = first; r < last; ++r) {
    double s[streams][3] = {};
    const std::int64_t begin = rows.row_start[r];
    for (std::int64_t k = begin; k < rows.row_start[r + 1]; ++k) {
      const double* xc = x + 3 * static_cast<std::int64_t>(rows.column[k]);
      double* stream = s[(k - begin) % streams];
      for (int i = 0; i < 3; ++i) stream[i] = stream[i] + scalars[k] * xc[i];
    }
    for (int i = 0; i < 3; ++i) y[3 * r + i] = (s[0][i] + s[1][i]) + (s[2][i] + s[3][i]);
  }
}

}  // namespace dgtex::kernels
