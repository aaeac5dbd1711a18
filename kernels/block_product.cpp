#include "dgtex/kernels/block_product.h"

#include <cstddef>
#include <type_traits>

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

// Adds to stream U, with Blocks the block `b`, with Scalars the scalar block m I (the same
// x: the first lanes of its spread node); c9: the node column's offset in the spread vectors.
template <int U, bool Blocks, bool Scalars, class V, int L, int NX>
__attribute__((always_inline)) inline void add_block(const double* __restrict b, double m,
                                                     const double* const* spread, std::int64_t c9,
                                                     RowSums<V, L, NX>& sums) {
  using Sums = RowSums<V, L, NX>;
  constexpr int NV = Sums::vectors, NS = Sums::scalar_vectors;
  constexpr int loaded = Blocks ? NV : NS;  // NS <= NV
#pragma GCC unroll 2
  for (int x = 0; x < NX; ++x) {
    const double* s = spread[x] + c9;
    V xs[NV];
#pragma GCC unroll 4
    for (int v = 0; v < loaded; ++v) __builtin_memcpy(&xs[v], s + v * L, sizeof(V));
    if constexpr (Blocks) {
#pragma GCC unroll 4
      for (int v = 0; v < NV; ++v) {
        V block;
        __builtin_memcpy(&block, b + v * L, sizeof(V));
        sums.lanes[x][U][v] = sums.lanes[x][U][v] + block * xs[v];
      }
      sums.last[x][U] = sums.last[x][U] + b[8] * s[8];
    }
    if constexpr (Scalars) {
#pragma GCC unroll 4
      for (int v = 0; v < NS; ++v) sums.scalar_lanes[U][v] = sums.scalar_lanes[U][v] + m * xs[v];
    }
  }
}

// Rows of K x (with Blocks; NX vectors) and of S x (with Scalars; NX = 1, S given by its
// scalars).
template <bool Blocks, bool Scalars, class V, int L, int NX>
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
    const auto block = [&](std::int64_t k) { return Blocks ? blocks + 9 * k : nullptr; };
    const auto scalar = [&](std::int64_t k) { return Scalars ? scalars[k] : 0.0; };
    const auto c9 = [&](std::int64_t k) { return 9 * static_cast<std::int64_t>(rows.column[k]); };
    const auto add = [&](auto stream, std::int64_t k) {
      add_block<decltype(stream)::value, Blocks, Scalars>(block(k), scalar(k), spread, c9(k), sums);
    };
    using S0 = std::integral_constant<int, 0>;
    using S1 = std::integral_constant<int, 1>;
    using S2 = std::integral_constant<int, 2>;
    using S3 = std::integral_constant<int, 3>;
    std::int64_t k = begin;
    for (; k + streams <= end; k += streams) {
      add(S0{}, k);
      add(S1{}, k + 1);
      add(S2{}, k + 2);
      add(S3{}, k + 3);
    }
    if (k < end) add(S0{}, k);
    if (k + 1 < end) add(S1{}, k + 1);
    if (k + 2 < end) add(S2{}, k + 2);
    if constexpr (Blocks) {
      for (int x = 0; x < NX; ++x) {
        double t[9];
        for (int v = 0; v < NV; ++v) {
          const V sum = (sums.lanes[x][0][v] + sums.lanes[x][1][v]) + (sums.lanes[x][2][v] + sums.lanes[x][3][v]);
          __builtin_memcpy(t + v * L, &sum, sizeof(V));
        }
        t[8] = (sums.last[x][0] + sums.last[x][1]) + (sums.last[x][2] + sums.last[x][3]);
        for (int i = 0; i < 3; ++i) y[x][3 * r + i] = (t[3 * i] + t[3 * i + 1]) + t[3 * i + 2];
      }
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

// One path: K x for `count` (1 or 2) vectors when blocks is non-null, and S x (one vector)
// when scalars is non-null.
#define DGTEX_BLOCK_ROWS_PATH(attribute, name, V, L)                                                               \
  attribute void block_rows_##name(BlockRows rows, std::int64_t first, std::int64_t last, const double* blocks,    \
                                   const double* scalars, const double* const* spread, double* const* y,           \
                                   double* y_scalars, int count) {                                                 \
    if (count == 2) block_rows<true, false, V, L, 2>(rows, first, last, blocks, nullptr, spread, y, nullptr);      \
    else if (!scalars) block_rows<true, false, V, L, 1>(rows, first, last, blocks, nullptr, spread, y, nullptr);   \
    else if (!blocks) block_rows<false, true, V, L, 1>(rows, first, last, nullptr, scalars, spread, y, y_scalars); \
    else block_rows<true, true, V, L, 1>(rows, first, last, blocks, scalars, spread, y, y_scalars);                \
  }
DGTEX_BLOCK_ROWS_PATH(__attribute__((target("avx512f"))), avx512, V8, 8)
DGTEX_BLOCK_ROWS_PATH(__attribute__((target("avx2"))), avx2, V4, 4)
DGTEX_BLOCK_ROWS_PATH(, baseline, V2, 2)
#undef DGTEX_BLOCK_ROWS_PATH

void block_rows_of(VectorPath path, BlockRows rows, std::int64_t first, std::int64_t last, const double* blocks,
                   const double* scalars, const double* const* spread, double* const* y, double* y_scalars,
                   int count) {
  kernel_of(path, block_rows_avx512, block_rows_avx2, block_rows_baseline)(rows, first, last, blocks, scalars, spread,
                                                                          y, y_scalars, count);
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
  block_rows_of(path, rows, first, last, nullptr, scalars, &spread, nullptr, y, 1);
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
