#include "multigrid_rows.h"

#include <type_traits>

#include <immintrin.h>

namespace dgtex::kernels::detail {
namespace {

#define DGTEX_ROW_INLINE __attribute__((always_inline)) inline

DGTEX_ROW_INLINE Lanes4 load4(const double* p) {
  Lanes4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
DGTEX_ROW_INLINE void store4(double* p, Lanes4 v) { std::memcpy(p, &v, sizeof v); }
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
    if (!needs_interior || four_interior_texels(row_bits + i0)) {
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
// b - A x of four interior texels (texel_residual's order).
DGTEX_ROW_INLINE Lanes4 interior_residual(const double* b, const double* x, std::int64_t t, std::int64_t s) {
  return load4(b + t) - interior_operator(x, t, s);
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
    if (four_interior_texels(bits + t)) {
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
        store_colour_lanes(r + t, first, interior_residual(b, x, t, s));
      },
      [&](int i, int lane) {
        const std::int64_t t = row + i;
        const std::uint8_t m = bits[t];
        if ((lane & 1) == first) r[t] = texel_residual(m, b, x, t, s);
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
        const Lanes4 v = interior_residual(b, x, t, s);
        store4(r + t, v);
        norm2 += v * v;
      },
      [&](int i, int lane) {
        const std::int64_t t = row + i;
        const std::uint8_t m = bits[t];
        const double value = texel_residual(m, b, x, t, s);
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

// A 4-lane vector of Real (the level-0 transfers below: four coarse nodes a group).
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

// The 9-point row loops work on vectors of Nine<Real>::lanes nodes: 4 doubles or 8 floats
// (one AVX register either way; two SSE registers on the baseline form). Lanes never mix,
// so the lane count does not change any result. 8 float lanes instead of 4: callgrind,
// open + spiral T = 1024, 1 thread: float sweeps 231M -> 185M, residuals 37M -> 19M
// instructions.
template <class Real>
struct Nine;
template <>
struct Nine<double> {
  static constexpr int lanes = 4;
  typedef double type __attribute__((vector_size(32)));
  typedef std::int64_t index __attribute__((vector_size(32)));
};
template <>
struct Nine<float> {
  static constexpr int lanes = 8;
  typedef float type __attribute__((vector_size(32)));
  typedef std::int32_t index __attribute__((vector_size(32)));
};
template <class Real>
DGTEX_ROW_INLINE typename Nine<Real>::type load_nine(const Real* p) {
  typename Nine<Real>::type v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
// Lanes k + shift of the pair (first, second), k = 0 .. lanes - 1 (shift 1: east
// neighbours from (current, next); shift lanes - 1: west neighbours from (previous, current)).
template <class Real, int shift>
DGTEX_ROW_INLINE typename Nine<Real>::type shifted(typename Nine<Real>::type first, typename Nine<Real>::type second) {
  using I = typename Nine<Real>::index;
  if constexpr (Nine<Real>::lanes == 4)
    return __builtin_shuffle(first, second, I{shift, shift + 1, shift + 2, shift + 3});
  else
    return __builtin_shuffle(first, second,
                             I{shift, shift + 1, shift + 2, shift + 3, shift + 4, shift + 5, shift + 6, shift + 7});
}

// Lane k holds k % 2 (the column parity of node t + k for an even t).
template <class Real>
DGTEX_ROW_INLINE typename Nine<Real>::index lane_parity() {
  using I = typename Nine<Real>::index;
  if constexpr (Nine<Real>::lanes == 4)
    return I{0, 1, 0, 1};
  else
    return I{0, 1, 0, 1, 0, 1, 0, 1};
}

// The eight off-diagonal products of the 9-point operator at t .. t + lanes - 1, in the
// order of the references (smooth_stencil9_color_reference, residual_stencil9_reference).
template <class Real>
struct Offdiagonal9 {
  using V = typename Nine<Real>::type;
  V term[8];
  // x_west, x_east: x(t - 1 ..), x(t + 1 ..).
  DGTEX_ROW_INLINE Offdiagonal9(const Stencil9ViewOf<Real>& a, const Real* x, std::int64_t t, std::int64_t s,
                                V x_west, V x_east) {
    auto L = [](const Real* p) { return load_nine(p); };
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
  DGTEX_ROW_INLINE V sum() const {
    V v = term[0];
    for (int k = 1; k < 8; ++k) v = v + term[k];
    return v;
  }
  // first + term 0 + ... + term 7, left to right.
  DGTEX_ROW_INLINE V sum_after(V first) const {
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
  using V = typename Nine<Real>::type;
  constexpr int L = Nine<Real>::lanes;
  const std::int64_t s = g.stride(), row = g.at(0, j);
  const int nx = g.nx;
  V previous = {};
  previous[L - 1] = x[row - 1];
  V current = nx >= L ? load_nine(x + row) : V{};
  int i0 = 0;
  for (; i0 + L <= nx; i0 += L) {
    const std::int64_t t = row + i0;
    V next = {};
    if (i0 + 2 * L <= nx)
      next = load_nine(x + t + L);
    else
      next[0] = x[t + L];  // the east ghost when the group ends the row; later lanes unused
    // The colour's lanes read only the other colour: all lanes see the old values.
    const Offdiagonal9<Real> offdiagonal(a, x, t, s, shifted<Real, L - 1>(previous, current),
                                         shifted<Real, 1>(current, next));
    const V c = load_nine(a.c + t);
    const V v = (load_nine(b + t) - offdiagonal.sum()) / c;
    // The colour's nodes with c > 0 take v, the others keep their loaded values: one store
    // of the whole group. No other thread touches row j meanwhile (stencil9_sweep: a row is
    // written in one phase, and no row of the same phase reads it), so rewriting the other
    // lanes unchanged is safe. Callgrind, 1 thread: the double sweep (open T = 256, 10
    // solves) 97M -> 59M, the float sweep (open + spiral T = 1024) 185M -> 91M instructions.
    const V zero = {};
    const V updated = ((lane_parity<Real>() == ci) & (c > zero)) ? v : current;
    std::memcpy(x + t, &updated, sizeof updated);
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
  using V = typename Nine<Real>::type;
  constexpr int L = Nine<Real>::lanes;
  int i0 = 0;
  for (; i0 + L <= nx; i0 += L) {
    const std::int64_t t = row + i0;
    const V c = load_nine(a.c + t);
    const V value = load_nine(b + t) - Offdiagonal9<Real>(a, x, t, s, load_nine(x + t - 1), load_nine(x + t + 1))
                                           .sum_after(c * load_nine(x + t));
    const V zero = {};
    const V masked = c > zero ? value : zero;
    std::memcpy(r + t, &masked, sizeof masked);
  }
  for (int i = i0; i < nx; ++i) {
    const std::int64_t t = row + i;
    r[t] = a.c[t] > 0 ? b[t] - stencil9_operator1(a, x, t, s) : Real(0);
  }
}

// Coarse row J of the red residual restricted to level 1 (restrict_red_residual_texels):
//   b_c(I, J) = r(2I, 2J) + sw(I, J) r(2I+1, 2J+1) + se(I-1, J) r(2I-1, 2J+1)
//             + nw(I, J-1) r(2I+1, 2J-1) + ne(I-1, J-1) r(2I-1, 2J-1),
// summed left to right in double and rounded once to Real. Four coarse nodes at a time read
// eight texels of each of the rows 2J and 2J -+ 1; when all 24 are interior texels their
// residuals are two vectors a row (the odd or even lanes are the ones needed), else the four
// nodes go one by one through the flag bytes. The cell centres west of a group are the last
// lanes of the group before (the ghost column's for I = 0).
// Four Real lanes as doubles.
DGTEX_ROW_INLINE Lanes4 widen_lanes_of(typename LanesOf<float>::type v) { return __builtin_convertvector(v, Lanes4); }
DGTEX_ROW_INLINE Lanes4 widen_lanes_of(Lanes4 v) { return v; }
template <class Real>
DGTEX_ROW_INLINE Lanes4 widen_lanes(const Real* p) {
  return widen_lanes_of(load_lanes(p));
}
DGTEX_ROW_INLINE bool eight_active(const std::uint8_t* active) {  // 0/1 bytes
  std::uint64_t word;
  std::memcpy(&word, active, sizeof word);
  return word == 0x0101010101010101u;
}
DGTEX_ROW_INLINE bool eight_interior(const std::uint8_t* bits) {
  std::uint64_t word;
  std::memcpy(&word, bits, sizeof word);
  return word == 0x0101010101010101u * interior_texel;
}

template <class Real>
DGTEX_ROW_INLINE void red_residual_restricted_impl(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p,
                                                   const std::uint8_t* bits, const double* b, const double* x,
                                                   Real* b_coarse, int J) {
  const std::int64_t s = fine.stride(), cs = coarse.stride();
  const std::int64_t row = coarse.at(0, J), f0 = fine.at(0, 2 * J);
  auto red_residual = [&](std::int64_t t) { return texel_residual(bits[t], b, x, t, s); };
  double west_north = red_residual(f0 + s - 1), west_south = red_residual(f0 - s - 1);
  auto one = [&](int I) {
    const std::int64_t c = row + I, f = f0 + 2 * I;
    const double east_north = red_residual(f + s + 1), east_south = red_residual(f - s + 1);
    b_coarse[c] = static_cast<Real>(red_residual(f) + p.sw[c] * east_north + p.se[c - 1] * west_north +
                                    p.nw[c - cs] * east_south + p.ne[c - cs - 1] * west_south);
    west_north = east_north;
    west_south = east_south;
  };
  int I0 = 0;
  for (; I0 + 4 <= coarse.nx && 2 * I0 + 8 <= fine.nx; I0 += 4) {
    const std::int64_t c = row + I0, f = f0 + 2 * I0;
    if (!(eight_interior(bits + f) && eight_interior(bits + f + s) && eight_interior(bits + f - s))) {
      for (int I = I0; I < I0 + 4; ++I) one(I);
      continue;
    }
    const Lanes4 centre = __builtin_shuffle(interior_residual(b, x, f, s), interior_residual(b, x, f + 4, s),
                                            Lanes4Index{0, 2, 4, 6});
    const Lanes4 north = __builtin_shuffle(interior_residual(b, x, f + s, s), interior_residual(b, x, f + s + 4, s),
                                           Lanes4Index{1, 3, 5, 7});
    const Lanes4 south = __builtin_shuffle(interior_residual(b, x, f - s, s), interior_residual(b, x, f - s + 4, s),
                                           Lanes4Index{1, 3, 5, 7});
    const Lanes4 north_west = __builtin_shuffle(Lanes4{0.0, 0.0, 0.0, west_north}, north, Lanes4Index{3, 4, 5, 6});
    const Lanes4 south_west = __builtin_shuffle(Lanes4{0.0, 0.0, 0.0, west_south}, south, Lanes4Index{3, 4, 5, 6});
    const Lanes4 sum = (((centre + widen_lanes(p.sw + c) * north) + widen_lanes(p.se + c - 1) * north_west) +
                        widen_lanes(p.nw + c - cs) * south) +
                       widen_lanes(p.ne + c - cs - 1) * south_west;
    if constexpr (std::is_same_v<Real, float>) {
      const typename LanesOf<float>::type rounded = __builtin_convertvector(sum, typename LanesOf<float>::type);
      std::memcpy(b_coarse + c, &rounded, sizeof rounded);
    } else {
      store4(b_coarse + c, sum);
    }
    west_north = north[3];
    west_south = south[3];
  }
  for (; I0 < coarse.nx; ++I0) one(I0);
}

// Fine row j of the coarse correction added at level 0's red nodes (prolong_correction_red):
// even rows get x_c(I, J) at (2I, 2J), odd rows the cell-centre interpolation at (2I+1, 2J+1),
// formed in Real as ((sw x_c + se x_c(east)) + nw x_c(north)) + ne x_c(north-east), both
// added in double. Four coarse nodes at a time cover eight texels; when all eight are active
// the two vectors of x are updated whole, their other lanes rewritten unchanged (selected
// from the loaded values, not added to zero, which would turn -0 into +0: no other thread
// writes this row meanwhile), else the texels go one by one.
template <class Real>
DGTEX_ROW_INLINE void prolong_correction_red_impl(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p,
                                                  const Real* x_coarse, const std::uint8_t* fine_active,
                                                  double* x_fine, int j) {
  const std::int64_t cs = coarse.stride(), row = fine.at(0, j), crow = coarse.at(0, j >> 1);
  const bool odd = j & 1;
  auto one = [&](int i) {
    const std::int64_t t = row + i, c = crow + (i >> 1);
    if (!fine_active[t]) return;
    if (odd)
      x_fine[t] += p.sw[c] * x_coarse[c] + p.se[c] * x_coarse[c + 1] + p.nw[c] * x_coarse[c + cs] +
                   p.ne[c] * x_coarse[c + cs + 1];
    else
      x_fine[t] += x_coarse[c];
  };
  int i0 = 0;
  for (; i0 + 8 <= fine.nx; i0 += 8) {
    const std::int64_t t = row + i0, c = crow + (i0 >> 1);
    if (!eight_active(fine_active + t)) {
      for (int i = i0 + odd; i < i0 + 8; i += 2) one(i);
      continue;
    }
    using V = typename LanesOf<Real>::type;
    Lanes4 correction;
    if (odd) {
      const V formed = load_lanes(p.sw + c) * load_lanes(x_coarse + c) +
                       load_lanes(p.se + c) * load_lanes(x_coarse + c + 1) +
                       load_lanes(p.nw + c) * load_lanes(x_coarse + c + cs) +
                       load_lanes(p.ne + c) * load_lanes(x_coarse + c + cs + 1);
      correction = widen_lanes_of(formed);
    } else {
      correction = widen_lanes(x_coarse + c);
    }
    const Lanes4 low = load4(x_fine + t), high = load4(x_fine + t + 4);
    // Lane k of the correction goes to texel i0 + 2k + odd.
    const Lanes4 spread_low = __builtin_shuffle(correction, Lanes4Index{0, 0, 1, 1});
    const Lanes4 spread_high = __builtin_shuffle(correction, Lanes4Index{2, 2, 3, 3});
    const Lanes4 sum_low = low + spread_low, sum_high = high + spread_high;
    const Lanes4Index keep = odd ? Lanes4Index{4, 1, 6, 3} : Lanes4Index{0, 5, 2, 7};
    store4(x_fine + t, __builtin_shuffle(sum_low, low, keep));
    store4(x_fine + t + 4, __builtin_shuffle(sum_high, high, keep));
  }
  for (int i = i0 + odd; i < fine.nx; i += 2) one(i);
}

// Fine row j of the coarse correction between 9-point levels (prolong_correction): every
// active fine node gets (P x_c) formed in Real as prolong_correction_plain forms it. Four
// coarse nodes at a time cover eight fine nodes; when all eight are active, the corrections
// of the even and odd fine columns are two vectors, interleaved and added to x whole.
template <class Real>
DGTEX_ROW_INLINE void prolong_correction_impl(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p,
                                              const Real* x_coarse, const std::uint8_t* fine_active, Real* x_fine,
                                              int j) {
  using V = typename LanesOf<Real>::type;
  using I = typename LanesOf<Real>::index;
  const std::int64_t cs = coarse.stride(), row = fine.at(0, j), crow = coarse.at(0, j >> 1);
  const bool odd_row = j & 1;
  const Real* x = x_coarse;
  auto one = [&](int i) {
    const std::int64_t c = crow + (i >> 1), t = row + i;
    if (!fine_active[t]) return;
    if (!odd_row)
      x_fine[t] += (i & 1) ? p.xw[c] * x[c] + p.xe[c] * x[c + 1] : x[c];
    else if (!(i & 1))
      x_fine[t] += p.ys[c] * x[c] + p.yn[c] * x[c + cs];
    else
      x_fine[t] += p.sw[c] * x[c] + p.se[c] * x[c + 1] + p.nw[c] * x[c + cs] + p.ne[c] * x[c + cs + 1];
  };
  int i0 = 0;
  for (; i0 + 8 <= fine.nx; i0 += 8) {
    const std::int64_t c = crow + (i0 >> 1), t = row + i0;
    if (!eight_active(fine_active + t)) {
      for (int i = i0; i < i0 + 8; ++i) one(i);
      continue;
    }
    auto L = [](const Real* q) { return load_lanes(q); };
    V even, odd;
    if (!odd_row) {
      even = L(x + c);
      odd = L(p.xw + c) * L(x + c) + L(p.xe + c) * L(x + c + 1);
    } else {
      even = L(p.ys + c) * L(x + c) + L(p.yn + c) * L(x + c + cs);
      odd = L(p.sw + c) * L(x + c) + L(p.se + c) * L(x + c + 1) + L(p.nw + c) * L(x + c + cs) +
            L(p.ne + c) * L(x + c + cs + 1);
    }
    const V low = L(x_fine + t) + __builtin_shuffle(even, odd, I{0, 4, 1, 5});
    const V high = L(x_fine + t + 4) + __builtin_shuffle(even, odd, I{2, 6, 3, 7});
    std::memcpy(x_fine + t, &low, sizeof low);
    std::memcpy(x_fine + t + 4, &high, sizeof high);
  }
  for (; i0 < fine.nx; ++i0) one(i0);
}

// The level-0 loops that read flag bytes, in AVX-512 (8 doubles a vector). Groups with other
// texels than interior ones (walls, cuts, Dirichlet data) stay vectors too: each neighbour
// term is masked to 0 by its coupling bit and the degree byte picks 1 / degree (or the
// degree), exactly the scalar forms' operations per lane. Why: in cut domains such groups are
// common, and the texel-by-texel loop of the 4-lane form took most of the colour sweep's time
// there (perf, spiral and accordion T = 256).
// GCC 12's AVX-512 intrinsics fill unused operands with _mm512_undefined_*(), which its
// -Wmaybe-uninitialized reports at every use (a header bug, fixed in GCC 13).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
namespace avx512 {
#define DGTEX_AVX512 __attribute__((target("avx512f"), always_inline)) inline

// x(t - 1 .. t + 6) and x(t + 1 .. t + 8) from x(t - 8 .. t - 1), x(t .. t + 7), x(t + 8 .. t + 15).
DGTEX_AVX512 __m512d west_of(__m512d previous, __m512d current) {
  return _mm512_castsi512_pd(_mm512_alignr_epi64(_mm512_castpd_si512(current), _mm512_castpd_si512(previous), 7));
}
DGTEX_AVX512 __m512d east_of(__m512d current, __m512d next) {
  return _mm512_castsi512_pd(_mm512_alignr_epi64(_mm512_castpd_si512(next), _mm512_castpd_si512(current), 1));
}
// Lane l: bits[l] as a 64-bit integer.
DGTEX_AVX512 __m512i widened_bits(const std::uint8_t* bits) {
  return _mm512_cvtepu8_epi64(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(bits)));
}
DGTEX_AVX512 __mmask8 lanes_with(__m512i bits, std::uint8_t flag) {
  return _mm512_test_epi64_mask(bits, _mm512_set1_epi64(flag));
}
// Lane l: laplace_degree(bits[l]) as an index, and the degree's entry of inverse_degree or
// the degree itself.
DGTEX_AVX512 __m512i degree_indices(__m512i bits) {
  return _mm512_and_si512(_mm512_srli_epi64(bits, degree_shift), _mm512_set1_epi64(7));
}
DGTEX_AVX512 __m512d inverse_degrees(__m512i bits) {
  return _mm512_permutexvar_pd(degree_indices(bits), _mm512_loadu_pd(inverse_degree));
}
DGTEX_AVX512 __m512d degrees(__m512i bits) {
  return _mm512_permutexvar_pd(degree_indices(bits), _mm512_set_pd(7, 6, 5, 4, 3, 2, 1, 0));
}

// Eight texels of one colour (b: their right-hand side): the smoothed values, in
// texel_smoothed's order ((((b + west) + east) + south) + north) / degree, and the lanes to store.
DGTEX_AVX512 __m512d smoothed_group(const std::uint8_t* bits, __m512d b, std::int64_t t, __m512d west,
                                    __m512d east, __m512d south, __m512d north, __mmask8 colour_lanes,
                                    __mmask8& stored) {
  __m512d sum = b;
  if (eight_interior(bits + t)) {
    stored = colour_lanes;
    sum = _mm512_add_pd(_mm512_add_pd(_mm512_add_pd(_mm512_add_pd(sum, west), east), south), north);
    return _mm512_mul_pd(sum, _mm512_set1_pd(0.25));
  }
  const __m512i m = widened_bits(bits + t);
  sum = _mm512_add_pd(sum, _mm512_maskz_mov_pd(lanes_with(m, couples_west_unknown), west));
  sum = _mm512_add_pd(sum, _mm512_maskz_mov_pd(lanes_with(m, couples_east_unknown), east));
  sum = _mm512_add_pd(sum, _mm512_maskz_mov_pd(lanes_with(m, couples_south_unknown), south));
  sum = _mm512_add_pd(sum, _mm512_maskz_mov_pd(lanes_with(m, couples_north_unknown), north));
  stored = colour_lanes & lanes_with(m, is_unknown);
  return _mm512_mul_pd(sum, inverse_degrees(m));
}

// The colour sweep. Masked stores write the colour's unknowns only, so the other colour's
// values, which another thread may read at a lagged block edge, are never rewritten. West and
// east neighbours come from registers, as in smooth_color_impl.
__attribute__((target("avx512f"))) void smooth_color(GridShape g, const std::uint8_t* bits, const double* b, double* x,
                                                     int j, int color) {
  const std::int64_t s = g.stride(), row = g.at(0, j);
  const int nx = g.nx;
  const int first = (color + j) & 1;
  const __mmask8 colour_lanes = first ? 0xAA : 0x55;
  __m512d previous = _mm512_maskz_broadcastsd_pd(0x80, _mm_set_sd(x[row - 1]));
  __m512d current = nx >= 8 ? _mm512_loadu_pd(x + row) : _mm512_setzero_pd();
  int i0 = 0;
  for (; i0 + 8 <= nx; i0 += 8) {
    const std::int64_t t = row + i0;
    // x(t + 8) is the east ghost when the group ends the row; lanes past it are not used.
    const __m512d next =
        i0 + 16 <= nx ? _mm512_loadu_pd(x + t + 8) : _mm512_maskz_broadcastsd_pd(0x01, _mm_set_sd(x[t + 8]));
    __mmask8 stored;
    const __m512d smoothed =
        smoothed_group(bits, _mm512_loadu_pd(b + t), t, west_of(previous, current), east_of(current, next),
                       _mm512_loadu_pd(x + t - s), _mm512_loadu_pd(x + t + s), colour_lanes, stored);
    _mm512_mask_storeu_pd(x + t, stored, smoothed);
    previous = current;
    current = next;
  }
  for (int i = i0 + first; i < nx; i += 2) {
    const std::int64_t t = row + i;
    if (bits[t] & is_unknown) x[t] = texel_smoothed(bits[t], b, x, t, s);
  }
}

// The row pairs' data that comes from beyond L2 (row j + 1 of x, or row j for
// red_from_zero_pair, and row j of b and of the flags: first touched by the pair at row j) is
// prefetched this many texels ahead (16 lines): open T = 1024, one thread, the sweep 0.95 ->
// 0.69 ms, two threads 0.34 -> 0.32 ms; 256 texels ahead gave the same.
constexpr int pair_prefetch_distance = 128;
// A prefetch hint for p + offset. On the last rows the address lies past the array (a
// prefetch never faults); forming it as an integer, or clamping it to the array, made the
// pair's code slower: the T = 256 and 512 sweep ~10-15 % (one thread, best of 5, twice).
template <class T>
DGTEX_AVX512 void prefetch_ahead(const T* p, std::int64_t offset) {
  _mm_prefetch(reinterpret_cast<const char*>(p + offset), _MM_HINT_T0);
}

// smooth_color(j, color), then smooth_color(j - 1, 1 - color), group by group: the sweep's
// first colour on row j and its lagged second colour on row j - 1 (lagged_rows). Both update
// the same columns' lanes. Row j - 1 is loaded once for both (the first colour's south
// neighbours, the second's own row), and the second colour's north neighbours are row j's
// updated values, from registers: 8 loads per eight texels instead of 10. Each texel sees
// the values it sees in the two separate calls (its neighbours of the other colour), so the
// bits are theirs.
__attribute__((target("avx512f"))) void smooth_color_pair(GridShape g, const std::uint8_t* bits, const double* b,
                                                          double* x, int j, int color) {
  const std::int64_t s = g.stride(), upper = g.at(0, j), lower = upper - s;
  const int nx = g.nx;
  const int first = (color + j) & 1;  // also the first column of colour 1 - color on row j - 1
  const __mmask8 colour_lanes = first ? 0xAA : 0x55;
  __m512d previous_upper = _mm512_maskz_broadcastsd_pd(0x80, _mm_set_sd(x[upper - 1]));
  __m512d previous_lower = _mm512_maskz_broadcastsd_pd(0x80, _mm_set_sd(x[lower - 1]));
  __m512d current_upper = nx >= 8 ? _mm512_loadu_pd(x + upper) : _mm512_setzero_pd();
  __m512d current_lower = nx >= 8 ? _mm512_loadu_pd(x + lower) : _mm512_setzero_pd();
  // Row j - 2 is loaded a group ahead, before the group's stores to row j: with the padded
  // stride (T + 2), x(j - 2, t) and x(j, t) lie 32 bytes apart modulo 4096 (T = 256, 1024),
  // so a load of row j - 2 right after a store to the same columns of row j looks like a
  // read of that store (4K aliasing) and waits for it (the sweep ran 20% slower than the two
  // calls at T = 256, one thread).
  __m512d south_lower = nx >= 8 ? _mm512_loadu_pd(x + lower - s) : _mm512_setzero_pd();
  int i0 = 0;
  for (; i0 + 8 <= nx; i0 += 8) {
    const std::int64_t tu = upper + i0, tl = lower + i0;
    const bool full = i0 + 16 <= nx;  // else x(t + 8) is the east ghost; lanes past it are not used
    const __m512d next_upper =
        full ? _mm512_loadu_pd(x + tu + 8) : _mm512_maskz_broadcastsd_pd(0x01, _mm_set_sd(x[tu + 8]));
    const __m512d next_lower =
        full ? _mm512_loadu_pd(x + tl + 8) : _mm512_maskz_broadcastsd_pd(0x01, _mm_set_sd(x[tl + 8]));
    const __m512d next_south_lower = full ? _mm512_loadu_pd(x + tl + 8 - s) : _mm512_setzero_pd();
    prefetch_ahead(x, tu + s + pair_prefetch_distance);
    prefetch_ahead(b, tu + pair_prefetch_distance);
    if ((i0 & 63) == 0) prefetch_ahead(bits, tu + pair_prefetch_distance);
    // b of both rows before the group's stores (4K aliasing: at T = 512 and 1024, b(j - 1, t) and
    // x(j, t) lie 16 bytes apart modulo 4096 when both arrays are page aligned, as large level
    // arrays are).
    const __m512d b_upper = _mm512_loadu_pd(b + tu), b_lower = _mm512_loadu_pd(b + tl);
    __mmask8 stored;
    const __m512d smoothed_upper =
        smoothed_group(bits, b_upper, tu, west_of(previous_upper, current_upper), east_of(current_upper, next_upper),
                       current_lower, _mm512_loadu_pd(x + tu + s), colour_lanes, stored);
    _mm512_mask_storeu_pd(x + tu, stored, smoothed_upper);
    const __m512d updated_upper = _mm512_mask_mov_pd(current_upper, stored, smoothed_upper);
    const __m512d smoothed_lower =
        smoothed_group(bits, b_lower, tl, west_of(previous_lower, current_lower), east_of(current_lower, next_lower),
                       south_lower, updated_upper, colour_lanes, stored);
    _mm512_mask_storeu_pd(x + tl, stored, smoothed_lower);
    previous_upper = current_upper, current_upper = next_upper;
    previous_lower = current_lower, current_lower = next_lower, south_lower = next_south_lower;
  }
  for (int i = i0 + first; i < nx; i += 2)
    if (bits[upper + i] & is_unknown) x[upper + i] = texel_smoothed(bits[upper + i], b, x, upper + i, s);
  for (int i = i0 + first; i < nx; i += 2)
    if (bits[lower + i] & is_unknown) x[lower + i] = texel_smoothed(bits[lower + i], b, x, lower + i, s);
}

// Eight texels of the first sweep from zero (b: their right-hand side): b / degree at the
// red unknowns (`red_lanes`), 0 in the other lanes.
DGTEX_AVX512 __m512d red_from_zero_group(const std::uint8_t* bits, __m512d b, std::int64_t t, __mmask8 red_lanes) {
  if (eight_interior(bits + t)) return _mm512_maskz_mul_pd(red_lanes, b, _mm512_set1_pd(0.25));
  const __m512i m = widened_bits(bits + t);
  return _mm512_maskz_mul_pd(red_lanes & lanes_with(m, is_unknown), b, inverse_degrees(m));
}
// The first sweep from zero on row j's texels from i0 on (those past the last whole group).
DGTEX_AVX512 void red_from_zero_tail(GridShape g, const std::uint8_t* bits, const double* b, double* x, int j,
                                     int i0) {
  const std::int64_t row = g.at(0, j);
  for (int i = i0; i < g.nx; ++i) {
    const std::int64_t t = row + i;
    const std::uint8_t m = bits[t];
    x[t] = ((m & is_unknown) && ((i + j) & 1) == 0) ? b[t] * inverse_degree[laplace_degree(m)] : 0.0;
  }
}

// red_from_zero(j), then smooth_color(j - 1, 1), group by group: the first sweep from zero
// with its lagged black colour, as smooth_color_pair (row j - 1's black texels lie under row
// j's red ones; their north neighbours are row j's new values, from registers).
__attribute__((target("avx512f"))) void red_from_zero_pair(GridShape g, const std::uint8_t* bits, const double* b,
                                                           double* x, int j) {
  const std::int64_t s = g.stride(), upper = g.at(0, j), lower = upper - s;
  const int nx = g.nx;
  const __mmask8 colour_lanes = (j & 1) ? 0xAA : 0x55;
  __m512d previous_lower = _mm512_maskz_broadcastsd_pd(0x80, _mm_set_sd(x[lower - 1]));
  __m512d current_lower = nx >= 8 ? _mm512_loadu_pd(x + lower) : _mm512_setzero_pd();
  __m512d south_lower = nx >= 8 ? _mm512_loadu_pd(x + lower - s) : _mm512_setzero_pd();  // a group ahead (4K aliasing)
  int i0 = 0;
  for (; i0 + 8 <= nx; i0 += 8) {
    const std::int64_t tu = upper + i0, tl = lower + i0;
    const bool full = i0 + 16 <= nx;
    const __m512d next_lower =
        full ? _mm512_loadu_pd(x + tl + 8) : _mm512_maskz_broadcastsd_pd(0x01, _mm_set_sd(x[tl + 8]));
    const __m512d next_south_lower = full ? _mm512_loadu_pd(x + tl + 8 - s) : _mm512_setzero_pd();
    prefetch_ahead(x, tu + pair_prefetch_distance);
    prefetch_ahead(b, tu + pair_prefetch_distance);
    if ((i0 & 63) == 0) prefetch_ahead(bits, tu + pair_prefetch_distance);
    const __m512d b_upper = _mm512_loadu_pd(b + tu), b_lower = _mm512_loadu_pd(b + tl);  // before the stores
    const __m512d red = red_from_zero_group(bits, b_upper, tu, colour_lanes);
    _mm512_storeu_pd(x + tu, red);
    __mmask8 stored;
    const __m512d smoothed_lower =
        smoothed_group(bits, b_lower, tl, west_of(previous_lower, current_lower), east_of(current_lower, next_lower),
                       south_lower, red, colour_lanes, stored);
    _mm512_mask_storeu_pd(x + tl, stored, smoothed_lower);
    previous_lower = current_lower, current_lower = next_lower, south_lower = next_south_lower;
  }
  red_from_zero_tail(g, bits, b, x, j, i0);
  for (int i = i0 + (j & 1); i < nx; i += 2)
    if (bits[lower + i] & is_unknown) x[lower + i] = texel_smoothed(bits[lower + i], b, x, lower + i, s);
}

// A x of eight texels: (((degree x - west) - east) - south) - north, each neighbour term
// masked to 0 by its coupling bit, as texel_operator forms it.
DGTEX_AVX512 __m512d texel_operators(__m512i m, const double* x, std::int64_t t, std::int64_t s) {
  __m512d v = _mm512_mul_pd(degrees(m), _mm512_loadu_pd(x + t));
  v = _mm512_sub_pd(v, _mm512_maskz_loadu_pd(lanes_with(m, couples_west_unknown), x + t - 1));
  v = _mm512_sub_pd(v, _mm512_maskz_loadu_pd(lanes_with(m, couples_east_unknown), x + t + 1));
  v = _mm512_sub_pd(v, _mm512_maskz_loadu_pd(lanes_with(m, couples_south_unknown), x + t - s));
  return _mm512_sub_pd(v, _mm512_maskz_loadu_pd(lanes_with(m, couples_north_unknown), x + t + s));
}
// interior_operator's order for eight interior texels.
DGTEX_AVX512 __m512d interior_operators(const double* x, std::int64_t t, std::int64_t s) {
  __m512d v = _mm512_mul_pd(_mm512_set1_pd(4.0), _mm512_loadu_pd(x + t));
  v = _mm512_sub_pd(v, _mm512_loadu_pd(x + t - 1));
  v = _mm512_sub_pd(v, _mm512_loadu_pd(x + t + 1));
  v = _mm512_sub_pd(v, _mm512_loadu_pd(x + t - s));
  return _mm512_sub_pd(v, _mm512_loadu_pd(x + t + s));
}
// A x of eight texels by the fast or the masked form; `unknowns` gets the lanes that are unknowns.
DGTEX_AVX512 __m512d operators(const std::uint8_t* bits, const double* x, std::int64_t t, std::int64_t s,
                               __mmask8& unknowns) {
  if (eight_interior(bits + t)) {
    unknowns = 0xff;
    return interior_operators(x, t, s);
  }
  const __m512i m = widened_bits(bits + t);
  unknowns = lanes_with(m, is_unknown);
  return texel_operators(m, x, t, s);
}

// Writes each group's result one group late, after the next group's loads: the output and x
// are page aligned alike, so the next group's x(t + 7 ..) read right after out(t ..) is
// written would look like a read of that store (4K aliasing) and wait for it. One thread,
// best of 6 runs: colour residual T = 256 35 -> 32 us, T = 512 154 -> 120 us; direction +
// operator 46 -> 38 and 190 -> 144 us.
struct LateStores {
  double* out;
  __mmask8 lanes;  // the lanes written
  __m512d pending = _mm512_setzero_pd();
  std::int64_t pending_t = -1;
  DGTEX_AVX512 void add(std::int64_t t, __m512d value) {
    flush();
    pending = value, pending_t = t;
  }
  DGTEX_AVX512 void flush() {
    if (pending_t >= 0) _mm512_mask_storeu_pd(out + pending_t, lanes, pending);
    pending_t = -1;
  }
};

__attribute__((target("avx512f"))) void residual_color(GridShape g, const std::uint8_t* bits, const double* b,
                                                       const double* x, double* r, int j, int color) {
  const std::int64_t s = g.stride(), row = g.at(0, j);
  const int first = (color + j) & 1;
  const __mmask8 colour_lanes = first ? 0xAA : 0x55;
  LateStores stores{r, colour_lanes};
  int i0 = 0;
  for (; i0 + 8 <= g.nx; i0 += 8) {
    const std::int64_t t = row + i0;
    __mmask8 unknowns;
    const __m512d ax = operators(bits, x, t, s, unknowns);
    stores.add(t, _mm512_maskz_sub_pd(unknowns, _mm512_loadu_pd(b + t), ax));
  }
  stores.flush();
  for (int i = i0 + first; i < g.nx; i += 2) r[row + i] = texel_residual(bits[row + i], b, x, row + i, s);
}

__attribute__((target("avx512f"))) void red_from_zero(GridShape g, const std::uint8_t* bits, const double* b,
                                                      double* x, int j) {
  const std::int64_t row = g.at(0, j);
  const __mmask8 red_lanes = (j & 1) ? 0xAA : 0x55;
  int i0 = 0;
  for (; i0 + 8 <= g.nx; i0 += 8)
    _mm512_storeu_pd(x + row + i0, red_from_zero_group(bits, _mm512_loadu_pd(b + row + i0), row + i0, red_lanes));
  red_from_zero_tail(g, bits, b, x, j, i0);
}

// Row sums keep RowSum's four chains: texel i is added to chain i mod 4 in increasing i, so
// the low half of a group goes in before the high half.
__attribute__((target("avx512f"))) double apply(GridShape g, const std::uint8_t* bits, const double* x, double* y,
                                               int j) {
  const std::int64_t s = g.stride(), row = g.at(0, j);
  __m256d dot = _mm256_setzero_pd();
  LateStores stores{y, 0xff};
  int i0 = 0;
  for (; i0 + 8 <= g.nx; i0 += 8) {
    const std::int64_t t = row + i0;
    __mmask8 unknowns;
    const __m512d ax = operators(bits, x, t, s, unknowns);
    const __m512d value = _mm512_maskz_mov_pd(unknowns, ax);
    const __m512d product = _mm512_mul_pd(value, _mm512_loadu_pd(x + t));
    stores.add(t, value);
    dot = _mm256_add_pd(dot, _mm512_castpd512_pd256(product));
    dot = _mm256_add_pd(dot, _mm512_extractf64x4_pd(product, 1));
  }
  stores.flush();
  alignas(32) double lane[4];
  _mm256_store_pd(lane, dot);
  for (int i = i0; i < g.nx; ++i) {
    const std::int64_t t = row + i;
    const std::uint8_t m = bits[t];
    const double value = (m & is_unknown) ? texel_operator(m, x, t, s) : 0.0;
    y[t] = value;
    lane[i & 3] += value * x[t];
  }
  return (lane[0] + lane[1]) + (lane[2] + lane[3]);
}
#undef DGTEX_AVX512
}  // namespace avx512
#pragma GCC diagnostic pop

// One set of row functions per instruction set: the same source, compiled for baseline
// x86-64 (SSE2: a 4-lane vector is two registers) and for AVX2 (one register).
#define DGTEX_TEXEL_ROW_KERNELS(ATTRIBUTE, NAME)                                                                     \
  ATTRIBUTE void NAME##_smooth_color_pair(GridShape g, const std::uint8_t* bits, const double* b, double* x,      \
                                         int j, int color) {                                                       \
    smooth_color_impl(g, bits, b, x, j, color);                                                                     \
    smooth_color_impl(g, bits, b, x, j - 1, 1 - color);                                                             \
  }                                                                                                                  \
  ATTRIBUTE void NAME##_red_from_zero_pair(GridShape g, const std::uint8_t* bits, const double* b, double* x,     \
                                          int j) {                                                                  \
    red_from_zero_impl(g, bits, b, x, j);                                                                           \
    smooth_color_impl(g, bits, b, x, j - 1, 1);                                                                     \
  }                                                                                                                  \
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
  const TexelRowKernels NAME = {NAME##_smooth_color, NAME##_smooth_color_pair, NAME##_red_from_zero,                \
                                NAME##_red_from_zero_pair, NAME##_residual_color, NAME##_residual, NAME##_apply,    \
                                NAME##_dot, NAME##_cg_update, NAME##_direction};                                     \
  template <class Real>                                                                                              \
  ATTRIBUTE void NAME##_smooth9_color(GridShape g, Stencil9ViewOf<Real> a, const Real* b, Real* x, int j, int ci) {  \
    stencil9_smooth_color_impl(g, a, b, x, j, ci);                                                                  \
  }                                                                                                                  \
  template <class Real>                                                                                              \
  ATTRIBUTE void NAME##_residual9(GridShape g, Stencil9ViewOf<Real> a, const Real* b, const Real* x, Real* r,        \
                                  int j) {                                                                          \
    stencil9_residual_impl(g, a, b, x, r, j);                                                                       \
  }                                                                                                                  \
  template <class Real>                                                                                              \
  ATTRIBUTE void NAME##_prolong9(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p, const Real* x_coarse, \
                                 const std::uint8_t* fine_active, Real* x_fine, int j) {                             \
    prolong_correction_impl(fine, coarse, p, x_coarse, fine_active, x_fine, j);                                     \
  }                                                                                                                  \
  const Stencil9RowKernels<double> NAME##_stencil9_double = {NAME##_smooth9_color<double>, NAME##_residual9<double>, \
                                                            NAME##_prolong9<double>};                               \
  const Stencil9RowKernels<float> NAME##_stencil9_float = {NAME##_smooth9_color<float>, NAME##_residual9<float>,     \
                                                          NAME##_prolong9<float>};                                  \
  template <class Real>                                                                                              \
  ATTRIBUTE void NAME##_red_residual_restricted(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p,       \
                                                const std::uint8_t* bits, const double* b, const double* x,          \
                                                Real* b_coarse, int J) {                                             \
    red_residual_restricted_impl(fine, coarse, p, bits, b, x, b_coarse, J);                                          \
  }                                                                                                                  \
  template <class Real>                                                                                              \
  ATTRIBUTE void NAME##_prolong_correction_red(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p,        \
                                               const Real* x_coarse, const std::uint8_t* fine_active,               \
                                               double* x_fine, int j) {                                              \
    prolong_correction_red_impl(fine, coarse, p, x_coarse, fine_active, x_fine, j);                                   \
  }                                                                                                                  \
  const TexelTransferRowKernels<double> NAME##_transfer_double = {NAME##_red_residual_restricted<double>,            \
                                                                  NAME##_prolong_correction_red<double>};           \
  const TexelTransferRowKernels<float> NAME##_transfer_float = {NAME##_red_residual_restricted<float>,              \
                                                                NAME##_prolong_correction_red<float>};

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

bool avx512_supported() {
  static const bool supported = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") != 0;
  }();
  return supported;
}

namespace {
// The AVX2 set with the AVX-512 forms of the level-0 loops that read flag bytes.
TexelRowKernels avx512_texel_rows() {
  TexelRowKernels rows = avx2_rows;
  rows.smooth_color = avx512::smooth_color;
  rows.smooth_color_pair = avx512::smooth_color_pair;
  rows.red_from_zero = avx512::red_from_zero;
  rows.red_from_zero_pair = avx512::red_from_zero_pair;
  rows.residual_color = avx512::residual_color;
  rows.apply = avx512::apply;
  return rows;
}
const TexelRowKernels avx512_rows = avx512_texel_rows();
}  // namespace

const TexelRowKernels& texel_rows(RowPath path) {
  return path == RowPath::avx512 ? avx512_rows : path == RowPath::avx2 ? avx2_rows : baseline_rows;
}
const TexelRowKernels& texel_rows() {
  return texel_rows(avx512_supported() ? RowPath::avx512 : avx2_supported() ? RowPath::avx2 : RowPath::baseline);
}

template <class Real>
const Stencil9RowKernels<Real>& stencil9_rows(RowPath path) {
  if constexpr (std::is_same_v<Real, float>)
    return path != RowPath::baseline ? avx2_rows_stencil9_float : baseline_rows_stencil9_float;
  else
    return path != RowPath::baseline ? avx2_rows_stencil9_double : baseline_rows_stencil9_double;
}
template <class Real>
const Stencil9RowKernels<Real>& stencil9_rows() {
  return stencil9_rows<Real>(avx2_supported() ? RowPath::avx2 : RowPath::baseline);
}
template <class Real>
const TexelTransferRowKernels<Real>& texel_transfer_rows(RowPath path) {
  if constexpr (std::is_same_v<Real, float>)
    return path != RowPath::baseline ? avx2_rows_transfer_float : baseline_rows_transfer_float;
  else
    return path != RowPath::baseline ? avx2_rows_transfer_double : baseline_rows_transfer_double;
}
template <class Real>
const TexelTransferRowKernels<Real>& texel_transfer_rows() {
  return texel_transfer_rows<Real>(avx2_supported() ? RowPath::avx2 : RowPath::baseline);
}
template const TexelTransferRowKernels<double>& texel_transfer_rows<double>(RowPath);
template const TexelTransferRowKernels<float>& texel_transfer_rows<float>(RowPath);
template const TexelTransferRowKernels<double>& texel_transfer_rows<double>();
template const TexelTransferRowKernels<float>& texel_transfer_rows<float>();
template const Stencil9RowKernels<double>& stencil9_rows<double>(RowPath);
template const Stencil9RowKernels<float>& stencil9_rows<float>(RowPath);
template const Stencil9RowKernels<double>& stencil9_rows<double>();
template const Stencil9RowKernels<float>& stencil9_rows<float>();

}  // namespace dgtex::kernels::detail
