#include "multigrid_rows.h"

#include <type_traits>

namespace dgtex::kernels::detail {
namespace {

#define DGTEX_ROW_INLINE __attribute__((always_inline)) inline

DGTEX_ROW_INLINE Lanes4 load4(const double* p) {
  Lanes4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
DGTEX_ROW_INLINE void store4(double* p, Lanes4 v) { std::memcpy(p, &v, sizeof v); }
DGTEX_ROW_INLINE bool four_interior(const std::uint8_t* bits) {
  std::uint32_t word;
  std::memcpy(&word, bits, sizeof word);
  return word == 0x01010101u * interior_texel;
}
DGTEX_ROW_INLINE double lanes_total(Lanes4 v) { return (v[0] + v[1]) + (v[2] + v[3]); }
// Stores lanes first and first + 2 of v (one colour of a group) and nothing else: the other
// lanes belong to the other colour, which other threads may read right now (lagged rows).
DGTEX_ROW_INLINE void store_colour_lanes(double* out, int first, Lanes4 v) {
  if (first == 0) {
    out[0] = v[0];
    out[2] = v[2];
  } else {
    out[1] = v[1];
    out[3] = v[3];
  }
}

// The group loop every kernel below shares: groups of four texels from i = 0; `full(i0)` for
// a complete group of four interior texels (when `needs_interior`), else `one(i, lane)` per
// texel of the group (lane = i mod 4, a constant after unrolling).
template <bool needs_interior, class Full, class One>
DGTEX_ROW_INLINE void for_groups(GridShape g, const std::uint8_t* row_bits, Full full, One one) {
  const int nx = g.nx;
  int i0 = 0;
  for (; i0 + 4 <= nx; i0 += 4) {
    if (!needs_interior || four_interior(row_bits + i0)) {
      full(i0);
    } else {
      for (int l = 0; l < 4; ++l) one(i0 + l, l);
    }
  }
  for (int l = 0; i0 + l < nx; ++l) one(i0 + l, l);
}

// (((4 x - west) - east) - south) - north, the order of texel_operator.
DGTEX_ROW_INLINE Lanes4 interior_operator(const double* x, std::int64_t t, std::int64_t s) {
  return (((4.0 * load4(x + t) - load4(x + t - 1)) - load4(x + t + 1)) - load4(x + t - s)) - load4(x + t + s);
}

typedef std::int64_t Lanes4Index __attribute__((vector_size(32)));
// x(t - 1 .. t + 2) and x(t + 1 .. t + 4) from the registers of x(t - 4 .. t - 1), x(t .. t + 3)
// and x(t + 4 .. t + 7).
DGTEX_ROW_INLINE Lanes4 west_of(Lanes4 previous, Lanes4 current) {
  return __builtin_shuffle(previous, current, Lanes4Index{3, 4, 5, 6});
}
DGTEX_ROW_INLINE Lanes4 east_of(Lanes4 current, Lanes4 next) {
  return __builtin_shuffle(current, next, Lanes4Index{1, 2, 3, 4});
}

// A colour sweep writes every other lane of the row it reads, so it takes the row's west and
// east neighbours from registers loaded ahead of the writes instead of loading x(t -+ 1):
// a vector load that overlaps a scalar store still in flight cannot be forwarded and waits
// for it (the first version, loading, swept at 13 GB/s against 18 before the vector path,
// T = 1024). The registers keep stale values in the lanes just written; only the other
// colour's lanes, which no colour sweep writes, are read from them. The loads of rows j -+ 1
// read lanes another thread may be updating at a block edge of the lagged rows; those lanes
// are never used.
DGTEX_ROW_INLINE void smooth_color_impl(GridShape g, const std::uint8_t* bits, const double* b, double* x, int j,
                                        int color) {
  const std::int64_t s = g.stride(), row = g.at(0, j);
  const int nx = g.nx;
  const int first = (color + j) & 1;  // first lane of the colour in every group (i0 is even)
  Lanes4 previous = {0.0, 0.0, 0.0, x[row - 1]};
  Lanes4 current = nx >= 4 ? load4(x + row) : Lanes4{};
  int i0 = 0;
  for (; i0 + 4 <= nx; i0 += 4) {
    const std::int64_t t = row + i0;
    // x(t + 4) is the east ghost when the group ends the row; lanes past it are not used.
    const Lanes4 next = i0 + 8 <= nx ? load4(x + t + 4) : Lanes4{x[t + 4], 0.0, 0.0, 0.0};
    if (four_interior(bits + t)) {
      // ((((b + west) + east) + south) + north) / 4, in texel_smoothed's order.
      const Lanes4 v =
          ((((load4(b + t) + west_of(previous, current)) + east_of(current, next)) + load4(x + t - s)) +
           load4(x + t + s)) *
          0.25;
      store_colour_lanes(x + t, first, v);
    } else {
      for (int lane = first; lane < 4; lane += 2)
        if (bits[t + lane] & is_unknown) x[t + lane] = texel_smoothed(bits[t + lane], b, x, t + lane, s);
    }
    previous = current;
    current = next;
  }
  for (int i = i0 + first; i < nx; i += 2) {
    const std::int64_t t = row + i;
    if (bits[t] & is_unknown) x[t] = texel_smoothed(bits[t], b, x, t, s);
  }
}

DGTEX_ROW_INLINE void red_from_zero_impl(GridShape g, const std::uint8_t* bits, const double* b, double* x, int j) {
  const std::int64_t row = g.at(0, j);
  const int red = j & 1;  // lane of the first red texel ((i + j) even) in every group
  for_groups<true>(
      g, bits + row,
      [&](int i0) {
        const std::int64_t t = row + i0;
        const Lanes4 v = load4(b + t) * 0.25;
        x[t + red] = v[red];
        x[t + red + 2] = v[red + 2];
        x[t + 1 - red] = 0.0;
        x[t + 3 - red] = 0.0;
      },
      [&](int i, int lane) {
        const std::int64_t t = row + i;
        const std::uint8_t m = bits[t];
        x[t] = ((m & is_unknown) && (lane & 1) == red) ? b[t] * inverse_degree[laplace_degree(m)] : 0.0;
      });
}

DGTEX_ROW_INLINE void residual_color_impl(GridShape g, const std::uint8_t* bits, const double* b, const double* x,
                                          double* r, int j, int color) {
  const std::int64_t s = g.stride(), row = g.at(0, j);
  const int first = (color + j) & 1;
  for_groups<true>(
      g, bits + row,
      [&](int i0) {
        const std::int64_t t = row + i0;
        store_colour_lanes(r + t, first, load4(b + t) - interior_operator(x, t, s));
      },
      [&](int i, int lane) {
        const std::int64_t t = row + i;
        const std::uint8_t m = bits[t];
        if ((lane & 1) == first) r[t] = (m & is_unknown) ? b[t] - texel_operator(m, x, t, s) : 0.0;
      });
}

DGTEX_ROW_INLINE double residual_impl(GridShape g, const std::uint8_t* bits, const double* b, const double* x,
                                      double* r, int j) {
  const std::int64_t s = g.stride(), row = g.at(0, j);
  Lanes4 norm2 = {0.0, 0.0, 0.0, 0.0};
  for_groups<true>(
      g, bits + row,
      [&](int i0) {
        const std::int64_t t = row + i0;
        const Lanes4 v = load4(b + t) - interior_operator(x, t, s);
        store4(r + t, v);
        norm2 += v * v;
      },
      [&](int i, int lane) {
        const std::int64_t t = row + i;
        const std::uint8_t m = bits[t];
        const double value = (m & is_unknown) ? b[t] - texel_operator(m, x, t, s) : 0.0;
        r[t] = value;
        norm2[lane] += value * value;
      });
  return lanes_total(norm2);
}

DGTEX_ROW_INLINE double apply_impl(GridShape g, const std::uint8_t* bits, const double* x, double* y, int j) {
  const std::int64_t s = g.stride(), row = g.at(0, j);
  Lanes4 dot = {0.0, 0.0, 0.0, 0.0};
  for_groups<true>(
      g, bits + row,
      [&](int i0) {
        const std::int64_t t = row + i0;
        const Lanes4 v = interior_operator(x, t, s);
        store4(y + t, v);
        dot += v * load4(x + t);
      },
      [&](int i, int lane) {
        const std::int64_t t = row + i;
        const std::uint8_t m = bits[t];
        const double value = (m & is_unknown) ? texel_operator(m, x, t, s) : 0.0;
        y[t] = value;
        dot[lane] += value * x[t];
      });
  return lanes_total(dot);
}

DGTEX_ROW_INLINE double dot_impl(GridShape g, const double* a, const double* b, int j) {
  const std::int64_t row = g.at(0, j);
  Lanes4 dot = {0.0, 0.0, 0.0, 0.0};
  for_groups<false>(
      g, nullptr, [&](int i0) { dot += load4(a + row + i0) * load4(b + row + i0); },
      [&](int i, int lane) { dot[lane] += a[row + i] * b[row + i]; });
  return lanes_total(dot);
}

DGTEX_ROW_INLINE double cg_update_impl(GridShape g, double alpha, const double* p, const double* q, double* x,
                                       double* r, int j) {
  const std::int64_t row = g.at(0, j);
  Lanes4 norm2 = {0.0, 0.0, 0.0, 0.0};
  for_groups<false>(
      g, nullptr,
      [&](int i0) {
        const std::int64_t t = row + i0;
        store4(x + t, load4(x + t) + alpha * load4(p + t));
        const Lanes4 v = load4(r + t) - alpha * load4(q + t);
        store4(r + t, v);
        norm2 += v * v;
      },
      [&](int i, int lane) {
        const std::int64_t t = row + i;
        x[t] += alpha * p[t];
        r[t] -= alpha * q[t];
        norm2[lane] += r[t] * r[t];
      });
  return lanes_total(norm2);
}

DGTEX_ROW_INLINE void direction_impl(GridShape g, const double* z, double beta, double* p, int j) {
  const std::int64_t row = g.at(0, j);
  for_groups<false>(
      g, nullptr, [&](int i0) { store4(p + row + i0, load4(z + row + i0) + beta * load4(p + row + i0)); },
      [&](int i, int) { p[row + i] = z[row + i] + beta * p[row + i]; });
}

// 9-point rows. A 4-lane vector of Real.
template <class Real>
struct LanesOf;
template <>
struct LanesOf<double> {
  typedef double type __attribute__((vector_size(32)));
  typedef std::int64_t index __attribute__((vector_size(32)));
};
template <>
struct LanesOf<float> {
  typedef float type __attribute__((vector_size(16)));
  typedef std::int32_t index __attribute__((vector_size(16)));
};
template <class Real>
DGTEX_ROW_INLINE typename LanesOf<Real>::type load_lanes(const Real* p) {
  typename LanesOf<Real>::type v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// The eight off-diagonal products of the 9-point operator at t .. t + 3, in the order of
// the references (smooth_stencil9_color_reference, residual_stencil9_reference).
template <class Real>
struct Offdiagonal4 {
  typename LanesOf<Real>::type term[8];
  // x_west, x_east: x(t - 1 .. t + 2), x(t + 1 .. t + 4).
  DGTEX_ROW_INLINE Offdiagonal4(const Stencil9ViewOf<Real>& a, const Real* x, std::int64_t t, std::int64_t s,
                                typename LanesOf<Real>::type x_west, typename LanesOf<Real>::type x_east) {
    auto L = [](const Real* p) { return load_lanes(p); };
    term[0] = L(a.e + t - 1) * x_west;
    term[1] = L(a.e + t) * x_east;
    term[2] = L(a.n + t - s) * L(x + t - s);
    term[3] = L(a.n + t) * L(x + t + s);
    term[4] = L(a.ne + t - s - 1) * L(x + t - s - 1);
    term[5] = L(a.nw + t - s + 1) * L(x + t - s + 1);
    term[6] = L(a.nw + t) * L(x + t + s - 1);
    term[7] = L(a.ne + t) * L(x + t + s + 1);
  }
  // term 0 + ... + term 7, left to right.
  DGTEX_ROW_INLINE typename LanesOf<Real>::type sum() const {
    auto v = term[0];
    for (int k = 1; k < 8; ++k) v = v + term[k];
    return v;
  }
  // first + term 0 + ... + term 7, left to right.
  DGTEX_ROW_INLINE typename LanesOf<Real>::type sum_after(typename LanesOf<Real>::type first) const {
    for (int k = 0; k < 8; ++k) first = first + term[k];
    return first;
  }
};
template <class Real>
DGTEX_ROW_INLINE Real stencil9_offdiagonal1(const Stencil9ViewOf<Real>& a, const Real* x, std::int64_t t,
                                            std::int64_t s) {
  return a.e[t - 1] * x[t - 1] + a.e[t] * x[t + 1] + a.n[t - s] * x[t - s] + a.n[t] * x[t + s] +
         a.ne[t - s - 1] * x[t - s - 1] + a.nw[t - s + 1] * x[t - s + 1] + a.nw[t] * x[t + s - 1] +
         a.ne[t] * x[t + s + 1];
}

template <class Real>
DGTEX_ROW_INLINE Real stencil9_operator1(const Stencil9ViewOf<Real>& a, const Real* x, std::int64_t t, std::int64_t s) {
  return a.c[t] * x[t] + a.e[t - 1] * x[t - 1] + a.e[t] * x[t + 1] + a.n[t - s] * x[t - s] + a.n[t] * x[t + s] +
         a.ne[t - s - 1] * x[t - s - 1] + a.nw[t - s + 1] * x[t - s + 1] + a.nw[t] * x[t + s - 1] +
         a.ne[t] * x[t + s + 1];
}

// As smooth_color_impl: the row's own west and east neighbours come from registers.
template <class Real>
DGTEX_ROW_INLINE void stencil9_smooth_color_impl(GridShape g, Stencil9ViewOf<Real> a, const Real* b, Real* x, int j,
                                                 int ci) {
  using V = typename LanesOf<Real>::type;
  using I = typename LanesOf<Real>::index;
  const std::int64_t s = g.stride(), row = g.at(0, j);
  const int nx = g.nx;
  V previous = {Real(0), Real(0), Real(0), x[row - 1]};
  V current = nx >= 4 ? load_lanes(x + row) : V{};
  int i0 = 0;
  for (; i0 + 4 <= nx; i0 += 4) {
    const std::int64_t t = row + i0;
    const V next = i0 + 8 <= nx ? load_lanes(x + t + 4) : V{x[t + 4], Real(0), Real(0), Real(0)};
    // The colour's lanes read only the other colour: all four lanes see the old values.
    const Offdiagonal4<Real> offdiagonal(a, x, t, s, __builtin_shuffle(previous, current, I{3, 4, 5, 6}),
                                         __builtin_shuffle(current, next, I{1, 2, 3, 4}));
    const V v = (load_lanes(b + t) - offdiagonal.sum()) / load_lanes(a.c + t);
    if (a.c[t + ci] > 0) x[t + ci] = v[ci];
    if (a.c[t + ci + 2] > 0) x[t + ci + 2] = v[ci + 2];
    previous = current;
    current = next;
  }
  for (int i = i0 + ci; i < nx; i += 2) {
    const std::int64_t t = row + i;
    if (a.c[t] > 0) x[t] = (b[t] - stencil9_offdiagonal1(a, x, t, s)) / a.c[t];
  }
}

template <class Real>
DGTEX_ROW_INLINE void stencil9_residual_impl(GridShape g, Stencil9ViewOf<Real> a, const Real* b, const Real* x,
                                             Real* r, int j) {
  const std::int64_t s = g.stride(), row = g.at(0, j);
  const int nx = g.nx;
  using V = typename LanesOf<Real>::type;
  int i0 = 0;
  for (; i0 + 4 <= nx; i0 += 4) {
    const std::int64_t t = row + i0;
    const V c = load_lanes(a.c + t);
    const V value = load_lanes(b + t) - Offdiagonal4<Real>(a, x, t, s, load_lanes(x + t - 1), load_lanes(x + t + 1))
                                                       .sum_after(c * load_lanes(x + t));
    const V zero = {};
    const V masked = c > zero ? value : zero;
    std::memcpy(r + t, &masked, sizeof masked);
  }
  for (int i = i0; i < nx; ++i) {
    const std::int64_t t = row + i;
    r[t] = a.c[t] > 0 ? b[t] - stencil9_operator1(a, x, t, s) : Real(0);
  }
}

// One set of row functions per instruction set: the same source, compiled for baseline
// x86-64 (SSE2: a 4-lane vector is two registers) and for AVX2 (one register).
#define DGTEX_TEXEL_ROW_KERNELS(ATTRIBUTE, NAME)                                                                     \
  ATTRIBUTE void NAME##_smooth_color(GridShape g, const std::uint8_t* bits, const double* b, double* x, int j,       \
                                     int color) {                                                                   \
    smooth_color_impl(g, bits, b, x, j, color);                                                                     \
  }                                                                                                                  \
  ATTRIBUTE void NAME##_red_from_zero(GridShape g, const std::uint8_t* bits, const double* b, double* x, int j) {    \
    red_from_zero_impl(g, bits, b, x, j);                                                                            \
  }                                                                                                                  \
  ATTRIBUTE void NAME##_residual_color(GridShape g, const std::uint8_t* bits, const double* b, const double* x,      \
                                       double* r, int j, int color) {                                               \
    residual_color_impl(g, bits, b, x, r, j, color);                                                                \
  }                                                                                                                  \
  ATTRIBUTE double NAME##_residual(GridShape g, const std::uint8_t* bits, const double* b, const double* x,          \
                                   double* r, int j) {                                                              \
    return residual_impl(g, bits, b, x, r, j);                                                                      \
  }                                                                                                                  \
  ATTRIBUTE double NAME##_apply(GridShape g, const std::uint8_t* bits, const double* x, double* y, int j) {          \
    return apply_impl(g, bits, x, y, j);                                                                            \
  }                                                                                                                  \
  ATTRIBUTE double NAME##_dot(GridShape g, const double* a, const double* b, int j) { return dot_impl(g, a, b, j); } \
  ATTRIBUTE double NAME##_cg_update(GridShape g, double alpha, const double* p, const double* q, double* x,          \
                                    double* r, int j) {                                                             \
    return cg_update_impl(g, alpha, p, q, x, r, j);                                                                 \
  }                                                                                                                  \
  ATTRIBUTE void NAME##_direction(GridShape g, const double* z, double beta, double* p, int j) {                     \
    direction_impl(g, z, beta, p, j);                                                                               \
  }                                                                                                                  \
  const TexelRowKernels NAME = {NAME##_smooth_color, NAME##_red_from_zero, NAME##_residual_color, NAME##_residual,  \
                                NAME##_apply,        NAME##_dot,           NAME##_cg_update,      NAME##_direction};  \
  template <class Real>                                                                                              \
  ATTRIBUTE void NAME##_smooth9_color(GridShape g, Stencil9ViewOf<Real> a, const Real* b, Real* x, int j, int ci) {  \
    stencil9_smooth_color_impl(g, a, b, x, j, ci);                                                                  \
  }                                                                                                                  \
  template <class Real>                                                                                              \
  ATTRIBUTE void NAME##_residual9(GridShape g, Stencil9ViewOf<Real> a, const Real* b, const Real* x, Real* r,        \
                                  int j) {                                                                          \
    stencil9_residual_impl(g, a, b, x, r, j);                                                                       \
  }                                                                                                                  \
  const Stencil9RowKernels<double> NAME##_stencil9_double = {NAME##_smooth9_color<double>,                          \
                                                            NAME##_residual9<double>};                              \
  const Stencil9RowKernels<float> NAME##_stencil9_float = {NAME##_smooth9_color<float>, NAME##_residual9<float>};

DGTEX_TEXEL_ROW_KERNELS(, baseline_rows)
DGTEX_TEXEL_ROW_KERNELS(__attribute__((target("avx2"))), avx2_rows)

#undef DGTEX_TEXEL_ROW_KERNELS
#undef DGTEX_ROW_INLINE

}  // namespace

bool avx2_supported() {
  static const bool supported = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
  }();
  return supported;
}

const TexelRowKernels& texel_rows(RowPath path) { return path == RowPath::avx2 ? avx2_rows : baseline_rows; }
const TexelRowKernels& texel_rows() { return texel_rows(avx2_supported() ? RowPath::avx2 : RowPath::baseline); }

template <class Real>
const Stencil9RowKernels<Real>& stencil9_rows(RowPath path) {
  if constexpr (std::is_same_v<Real, float>)
    return path == RowPath::avx2 ? avx2_rows_stencil9_float : baseline_rows_stencil9_float;
  else
    return path == RowPath::avx2 ? avx2_rows_stencil9_double : baseline_rows_stencil9_double;
}
template <class Real>
const Stencil9RowKernels<Real>& stencil9_rows() {
  return stencil9_rows<Real>(avx2_supported() ? RowPath::avx2 : RowPath::baseline);
}
template const Stencil9RowKernels<double>& stencil9_rows<double>(RowPath);
template const Stencil9RowKernels<float>& stencil9_rows<float>(RowPath);
template const Stencil9RowKernels<double>& stencil9_rows<double>();
template const Stencil9RowKernels<float>& stencil9_rows<float>();

}  // namespace dgtex::kernels::detail
