#include "dgtex/kernels/multigrid_galerkin.h"

#include <optional>
#include <vector>

#include "dgtex/kernels/multigrid_unknowns.h"
#include "multigrid_rows.h"
#include "multigrid_uniform_window.h"

namespace dgtex::kernels {
namespace {

// Values of one node's interpolation weights and of a translation-invariant 9-point row.
template <class Real>
struct InterpolationWeights {
  Real xw, xe, ys, yn, sw, se, nw, ne;
};
template <class Real>
struct Stencil9Row {
  Real c, e, n, ne, nw;
};

// Entry A(t, t + dx + dy * stride) of the level-0 texel operator (dx, dy in -1..1).
struct TexelOperator {
  const std::uint8_t* bits;
  double operator()(std::int64_t t, int dx, int dy) const {
    const std::uint8_t m = bits[t];
    if (dx == 0 && dy == 0) return (m & is_unknown) ? laplace_degree(m) : 0.0;
    if (dy == 0) return (m & (dx < 0 ? couples_west_unknown : couples_east_unknown)) ? -1.0 : 0.0;
    if (dx == 0) return (m & (dy < 0 ? couples_south_unknown : couples_north_unknown)) ? -1.0 : 0.0;
    return 0.0;
  }
};

// Entry of a symmetric 9-point operator (multigrid_grid.h), in double or float.
template <class Real>
struct Stencil9Operator {
  Stencil9ViewOf<Real> a;
  std::int64_t s;
  [[gnu::always_inline]] double operator()(std::int64_t t, int dx, int dy) const {
    switch ((dx + 1) + 3 * (dy + 1)) {
      case 0: return a.ne[t - s - 1];  // south-west
      case 1: return a.n[t - s];       // south
      case 2: return a.nw[t - s + 1];  // south-east
      case 3: return a.e[t - 1];       // west
      case 4: return a.c[t];
      case 5: return a.e[t];           // east
      case 6: return a.nw[t];          // north-west
      case 7: return a.n[t];           // north
      default: return a.ne[t];         // north-east
    }
  }
};

// The 5-point operator the interpolation of a 9-point level is built from (multigrid_galerkin.h):
// each diagonal coupling goes half to each of the two axis neighbours next to it that the
// node couples to, all to the one if only one is coupled, and to the centre if neither is
// (row sums are kept). A zero axis coupling (a wall) stays exactly zero.
// always_inline (also Stencil9Operator): GCC did not inline the float instantiation into
// build_interpolation (open T = 1024 setup +3 ms, 1 thread).
template <class Real>
struct LumpedStencil9Operator {
  Stencil9Operator<Real> a;
  [[gnu::always_inline]] double operator()(std::int64_t t, int dx, int dy) const {
    if (dx == 0 && dy == 0) {
      double centre = a(t, 0, 0);
      for (int ey = -1; ey <= 1; ey += 2)
        for (int ex = -1; ex <= 1; ex += 2)
          if (a(t, ex, 0) == 0.0 && a(t, 0, ey) == 0.0) centre += a(t, ex, ey);
      return centre;
    }
    if (dx != 0 && dy != 0) return 0.0;
    double coupling = a(t, dx, dy);
    if (coupling == 0.0) return 0.0;
    // The two diagonal neighbours next to (dx, dy) are (dx, dy) +- (dy, dx); the other axis
    // neighbour next to each of them is +-(dy, dx).
    for (int k = -1; k <= 1; k += 2) {
      const double diagonal = a(t, dx + k * dy, dy + k * dx);
      if (diagonal != 0.0) coupling += a(t, k * dy, k * dx) != 0.0 ? 0.5 * diagonal : diagonal;
    }
    return coupling;
  }
};

// A weight -numerator / denominator, or 0 where the denominator vanishes (a node that is
// no unknown, or one coupled only across the collapsed direction: no coarse representation).
inline double weight(double numerator, double denominator, double diagonal) {
  return (diagonal > 0 && denominator > 1e-12 * diagonal) ? -numerator / denominator : 0.0;
}

template <class Real>
struct UniformRegion;  // below

// Black-box interpolation for a 5-point operator a(t, dx, dy) (centre and axis entries).
// Weights are formed in double and stored as Real (pass 2 reads the stored pass-1 weights).
// With `uniform`: coarse nodes whose window is uniform get the uniform weights.
template <class Operator, class Real>
void build_interpolation(GridShape fine, const Operator& a, InterpolationArraysOf<Real> p, Execution execution,
                         const UniformRegion<Real>* uniform = nullptr) {
  const GridShape coarse = fine.coarser();
  const std::int64_t cs = coarse.stride();
  const std::uint8_t* fast = uniform ? uniform->windows.data() : nullptr;
  // Pass 1: fine nodes on coarse grid lines, from the stencil collapsed across the line.
  // Pass 2: cell-centre fine nodes, from their axis couplings and the pass-1 weights.
  forall_then(
      coarse.ny,
      [&](std::int64_t J64) {
        const int J = static_cast<int>(J64);
        for (int I = 0; I < coarse.nx; ++I) {
          const std::int64_t c = coarse.at(I, J);
          if (fast && fast[c]) {
            p.xw[c] = uniform->weights.xw, p.xe[c] = uniform->weights.xe;
            p.ys[c] = uniform->weights.ys, p.yn[c] = uniform->weights.yn;
            continue;
          }
          p.xw[c] = p.xe[c] = p.ys[c] = p.yn[c] = Real(0);
          if (2 * I + 1 < fine.nx) {
            const std::int64_t f = fine.at(2 * I + 1, 2 * J);
            const double diagonal = a(f, 0, 0), centre = diagonal + a(f, 0, -1) + a(f, 0, 1);
            p.xw[c] = static_cast<Real>(weight(a(f, -1, 0), centre, diagonal));
            p.xe[c] = static_cast<Real>(weight(a(f, 1, 0), centre, diagonal));
          }
          if (2 * J + 1 < fine.ny) {
            const std::int64_t f = fine.at(2 * I, 2 * J + 1);
            const double diagonal = a(f, 0, 0), centre = diagonal + a(f, -1, 0) + a(f, 1, 0);
            p.ys[c] = static_cast<Real>(weight(a(f, 0, -1), centre, diagonal));
            p.yn[c] = static_cast<Real>(weight(a(f, 0, 1), centre, diagonal));
          }
        }
      },
      coarse.ny,
      [&](std::int64_t J64) {
        const int J = static_cast<int>(J64);
        for (int I = 0; I < coarse.nx; ++I) {
          const std::int64_t c = coarse.at(I, J);
          if (fast && fast[c]) {
            p.sw[c] = uniform->weights.sw, p.se[c] = uniform->weights.se;
            p.nw[c] = uniform->weights.nw, p.ne[c] = uniform->weights.ne;
            continue;
          }
          p.sw[c] = p.se[c] = p.nw[c] = p.ne[c] = Real(0);
          if (2 * I + 1 >= fine.nx || 2 * J + 1 >= fine.ny) continue;
          const std::int64_t f = fine.at(2 * I + 1, 2 * J + 1);
          const double d = a(f, 0, 0);
          if (!(d > 0)) continue;
          const double as = a(f, 0, -1), an = a(f, 0, 1), aw = a(f, -1, 0), ae = a(f, 1, 0);
          p.sw[c] = static_cast<Real>(-(as * p.xw[c] + aw * p.ys[c]) / d);
          p.se[c] = static_cast<Real>(-(as * p.xe[c] + ae * p.ys[c + 1]) / d);
          p.nw[c] = static_cast<Real>(-(an * p.xw[c + cs] + aw * p.yn[c]) / d);
          p.ne[c] = static_cast<Real>(-(an * p.xe[c + cs] + ae * p.yn[c + 1]) / d);
        }
      },
      execution);
}

// Compile-time view of the fine operators for the Galerkin product: entry<OX, OY>(f) is
// A(f, f + OX + OY * stride); `couples<OX, OY>` says whether the entry can be non-zero at
// all (the 5-point texel operator has no diagonal couplings), so whole terms vanish at
// compile time instead of being multiplied by zero.
struct TexelEntries {
  const std::uint8_t* bits;
  template <int OX, int OY>
  static constexpr bool couples = (OX == 0 || OY == 0);
  bool has_unknown(std::int64_t f) const { return bits[f] & is_unknown; }
  template <int OX, int OY>
  double entry(std::int64_t f) const {
    const std::uint8_t m = bits[f];
    if constexpr (OX == 0 && OY == 0) return laplace_degree(m);
    else if constexpr (OX == -1) return (m & couples_west_unknown) ? -1.0 : 0.0;
    else if constexpr (OX == 1) return (m & couples_east_unknown) ? -1.0 : 0.0;
    else if constexpr (OY == -1) return (m & couples_south_unknown) ? -1.0 : 0.0;
    else return (m & couples_north_unknown) ? -1.0 : 0.0;
  }
};
template <class Real>
struct Stencil9Entries {
  Stencil9ViewOf<Real> a;
  std::int64_t s;
  template <int OX, int OY>
  static constexpr bool couples = true;
  bool has_unknown(std::int64_t f) const { return a.c[f] > 0; }
  template <int OX, int OY>
  double entry(std::int64_t f) const {
    if constexpr (OX == 0 && OY == 0) return a.c[f];
    else if constexpr (OX == 1 && OY == 0) return a.e[f];
    else if constexpr (OX == -1 && OY == 0) return a.e[f - 1];
    else if constexpr (OX == 0 && OY == 1) return a.n[f];
    else if constexpr (OX == 0 && OY == -1) return a.n[f - s];
    else if constexpr (OX == 1 && OY == 1) return a.ne[f];
    else if constexpr (OX == -1 && OY == -1) return a.ne[f - s - 1];
    else if constexpr (OX == -1 && OY == 1) return a.nw[f];
    else return a.nw[f - s + 1];  // (1, -1): south-east
  }
};

// The Galerkin row of one coarse node C = (I, J): acc[dJ + 1][dI + 1] accumulates
// (P^T A P)(C, (I + dI, J + dJ)). Every offset is a template argument, so the 9 x 9 x 4
// loop nest of the definition unrolls into straight-line code (no parity switches).
template <class Entries, class Real>
struct GalerkinRow {
  const Entries& a;
  const InterpolationViewOf<Real>& p;
  std::int64_t c, cs, f0, fs;  // coarse index and stride, fine index of (2I, 2J) and stride
  double acc[3][3] = {};

  // acc += v * P(g, .) for the fine node g = (2I + GX, 2J + GY), GX, GY in -2..2.
  template <int GX, int GY>
  void add_interpolated(double v) {
    constexpr int px = GX & 1, py = GY & 1;
    constexpr int bx = (GX - px) / 2, by = (GY - py) / 2;  // g's base coarse node (I + bx, J + by)
    const std::int64_t cb = c + bx + by * cs;
    if constexpr (px == 0 && py == 0) {
      acc[by + 1][bx + 1] += v;
    } else if constexpr (py == 0) {
      acc[by + 1][bx + 1] += v * p.xw[cb];
      acc[by + 1][bx + 2] += v * p.xe[cb];
    } else if constexpr (px == 0) {
      acc[by + 1][bx + 1] += v * p.ys[cb];
      acc[by + 2][bx + 1] += v * p.yn[cb];
    } else {
      acc[by + 1][bx + 1] += v * p.sw[cb];
      acc[by + 1][bx + 2] += v * p.se[cb];
      acc[by + 2][bx + 1] += v * p.nw[cb];
      acc[by + 2][bx + 2] += v * p.ne[cb];
    }
  }

  // P(f, C) for f = (2I + DI, 2J + DJ), DI, DJ in -1..1.
  template <int DI, int DJ>
  double column() const {
    if constexpr (DJ == -1) return DI == -1 ? p.ne[c - cs - 1] : DI == 0 ? p.yn[c - cs] : p.nw[c - cs];
    else if constexpr (DJ == 0) return DI == -1 ? p.xe[c - 1] : DI == 0 ? Real(1) : p.xw[c];
    else return DI == -1 ? p.se[c - 1] : DI == 0 ? p.ys[c] : p.sw[c];
  }

  template <int DI, int DJ, int OX, int OY>
  void couple(std::int64_t f, double pfc) {
    if constexpr (Entries::template couples<OX, OY>) {
      const double afg = a.template entry<OX, OY>(f);
      if (afg != 0.0) add_interpolated<DI + OX, DJ + OY>(pfc * afg);
    }
  }

  template <int DI, int DJ>
  void visit() {
    const double pfc = column<DI, DJ>();
    if (pfc == 0.0) return;
    const std::int64_t f = f0 + DI + DJ * fs;
    if (!a.has_unknown(f)) return;
    couple<DI, DJ, -1, -1>(f, pfc); couple<DI, DJ, 0, -1>(f, pfc); couple<DI, DJ, 1, -1>(f, pfc);
    couple<DI, DJ, -1, 0>(f, pfc);  couple<DI, DJ, 0, 0>(f, pfc);  couple<DI, DJ, 1, 0>(f, pfc);
    couple<DI, DJ, -1, 1>(f, pfc);  couple<DI, DJ, 0, 1>(f, pfc);  couple<DI, DJ, 1, 1>(f, pfc);
  }

  void run() {
    visit<-1, -1>(); visit<0, -1>(); visit<1, -1>();
    visit<-1, 0>();  visit<0, 0>();  visit<1, 0>();
    visit<-1, 1>();  visit<0, 1>();  visit<1, 1>();
  }
};

// 1 per coarse node whose eight interpolation weights equal `w` bitwise (ghosts: 0).
template <class Real>
std::vector<std::uint8_t> weights_equal(GridShape coarse, InterpolationViewOf<Real> p,
                                        const InterpolationWeights<Real>& w, Execution execution) {
  std::vector<std::uint8_t> equal(coarse.padded_size(), 0);
  forall(
      coarse.ny,
      [&, p, w](std::int64_t J) {  // copies: the byte stores below may alias them
        const std::int64_t row = coarse.at(0, static_cast<int>(J));
        for (std::int64_t c = row; c < row + coarse.nx; ++c)
          equal[c] = (p.xw[c] == w.xw) & (p.xe[c] == w.xe) & (p.ys[c] == w.ys) & (p.yn[c] == w.yn) &
                     (p.sw[c] == w.sw) & (p.se[c] == w.se) & (p.nw[c] == w.nw) & (p.ne[c] == w.ne);
      },
      execution);
  return equal;
}

// Fine nodes outside the fine grid have P(f, C) = 0 (the interpolation arrays hold 0 there
// and at ghosts), and ghost operator entries are 0, so no bounds checks are needed.
// Sums in double, stored as Real. With `uniform`: a coarse node whose window is uniform and
// whose 3 x 3 coarse neighbours (all whose weights GalerkinRow reads) are marked in
// `uniform_weights` (their weights are the uniform ones) gets the uniform row.
template <class Entries, class Real>
void galerkin(GridShape fine, const Entries& a, InterpolationViewOf<Real> p, Stencil9ArraysOf<Real> out,
              Execution execution, const UniformRegion<Real>* uniform = nullptr,
              const std::uint8_t* uniform_weights = nullptr) {
  const GridShape coarse = fine.coarser();
  const std::int64_t cs = coarse.stride(), fs = fine.stride();
  const std::uint8_t* w = uniform_weights;
  forall(
      coarse.ny,
      [&](std::int64_t J64) {
        const int J = static_cast<int>(J64);
        for (int I = 0; I < coarse.nx; ++I) {
          const std::int64_t c = coarse.at(I, J);
          if (w && uniform->windows[c] && (w[c - cs - 1] & w[c - cs] & w[c - cs + 1] & w[c - 1] & w[c] &
                                                 w[c + 1] & w[c + cs - 1] & w[c + cs] & w[c + cs + 1])) {
            out.c[c] = uniform->row.c, out.e[c] = uniform->row.e, out.n[c] = uniform->row.n;
            out.ne[c] = uniform->row.ne, out.nw[c] = uniform->row.nw;
            continue;
          }
          GalerkinRow<Entries, Real> row{a, p, c, cs, fine.at(2 * I, 2 * J), fs};
          row.run();
          out.c[c] = static_cast<Real>(row.acc[1][1]);
          out.e[c] = static_cast<Real>(row.acc[1][2]);
          out.n[c] = static_cast<Real>(row.acc[2][1]);
          out.ne[c] = static_cast<Real>(row.acc[2][2]);
          out.nw[c] = static_cast<Real>(row.acc[2][0]);
        }
      },
      execution);
}

// Uniform regions. Why: away from walls, Dirichlet texels and the tile's edge every fine
// row is the same translation-invariant stencil, so the interpolation weights and the
// Galerkin row of every coarse node there are the same too. They are computed once, by the code above, on a small
// grid filled with that stencil (ghosts included), and copied wherever every value the code
// would read equals the small grid's (the window of multigrid_uniform_window.h, and for the
// Galerkin row also the interpolation weights it reads, compared as stored). The general
// code gives such a node the same bits (same operations on the same values; this file is
// compiled without FMA contraction), so results do not depend on which path a node takes.
// What the window (x, y in 2I - 2 .. 2I + 3) must cover: a 9-point row of fine node f is read
// from the arrays at f, f - 1, f - s and f - s -+ 1. The weights of (I, J) read the rows of
// (2I+1, 2J), (2I, 2J+1), (2I+1, 2J+1) and, through the pass-1 weights of (I+1, J) and
// (I, J+1), of (2I+2, 2J+1) and (2I+1, 2J+2): arrays within 2I - 1 .. 2I + 3. The Galerkin
// row reads the rows of the 3 x 3 fine nodes around (2I, 2J) (arrays within 2I - 2 .. 2I + 2)
// and the weights of the 3 x 3 coarse nodes around (I, J), checked on their own.
// Measured (callgrind, `dgtex bench laplace --sizes 1024 --domains open spiral --solvers
// multigrid --repeat 1`, 1 thread): building the coarse levels 737M -> 276M instructions;
// the whole setup with the classification's rework 1129M -> 340M.
template <class Real>
struct UniformRegion {
  std::vector<std::uint8_t> windows;  // per coarse node (padded): its window is uniform
  InterpolationWeights<Real> weights;
  Stencil9Row<Real> row;  // the coarse operator's row there (c, e, n, ne, nw)
};

// The uniform weights and coarse row: those of coarse node (1, 1) when `interpolate` and
// `multiply` run the general code on a fine 8 x 8 grid that holds the uniform stencil
// everywhere, ghosts included (every value that node's results read lies in that grid).
template <class Real, class Interpolate, class Multiply>
void uniform_results(UniformRegion<Real>& region, const Interpolate& interpolate, const Multiply& multiply) {
  const GridShape fine{8, 8}, coarse = fine.coarser();
  std::vector<Real> p[8], a[5];
  for (auto& v : p) v.assign(coarse.padded_size(), Real(0));
  for (auto& v : a) v.assign(coarse.padded_size(), Real(0));
  const InterpolationArraysOf<Real> pa{p[0].data(), p[1].data(), p[2].data(), p[3].data(),
                                      p[4].data(), p[5].data(), p[6].data(), p[7].data()};
  interpolate(fine, pa);
  multiply(fine, pa.view(), Stencil9ArraysOf<Real>{a[0].data(), a[1].data(), a[2].data(), a[3].data(), a[4].data()});
  const std::int64_t c = coarse.at(1, 1);
  region.weights = {p[0][c], p[1][c], p[2][c], p[3][c], p[4][c], p[5][c], p[6][c], p[7][c]};
  region.row = {a[0][c], a[1][c], a[2][c], a[3][c], a[4][c]};
}

// Level 0: the uniform fine row is an unknown texel coupled to four unknowns.
template <class Real>
UniformRegion<Real> uniform_texel_region(GridShape fine, const std::uint8_t* bits, Execution execution) {
  UniformRegion<Real> region;
  const std::vector<std::uint8_t> filled(GridShape{8, 8}.padded_size(), interior_texel);
  uniform_results(
      region,
      [&](GridShape g, InterpolationArraysOf<Real> p) {
        build_interpolation(g, TexelOperator{filled.data()}, p, Execution::serial);
      },
      [&](GridShape g, InterpolationViewOf<Real> p, Stencil9ArraysOf<Real> out) {
        galerkin(g, TexelEntries{filled.data()}, p, out, Execution::serial);
      });
  region.windows =
      detail::uniform_windows(fine, [bits](std::int64_t f) { return bits[f] == interior_texel; }, execution);
  return region;
}

// A 9-point level: the uniform row is taken from the first of a few sample nodes whose
// 3 x 3 neighbourhood holds its values (none found: no uniform region, all nodes general).
template <class Real>
std::optional<UniformRegion<Real>> uniform_stencil9_region(GridShape fine, Stencil9ViewOf<Real> a,
                                                           Execution execution) {
  auto same = [&](std::int64_t f, std::int64_t g) {
    return a.c[f] == a.c[g] && a.e[f] == a.e[g] && a.n[f] == a.n[g] && a.ne[f] == a.ne[g] && a.nw[f] == a.nw[g];
  };
  constexpr int samples = 5;
  std::int64_t found = -1;
  for (int sj = 1; sj <= samples && found < 0; ++sj)
    for (int si = 1; si <= samples && found < 0; ++si) {
      const int i = fine.nx * si / (samples + 1), j = fine.ny * sj / (samples + 1);
      if (i < 1 || j < 1 || i + 1 >= fine.nx || j + 1 >= fine.ny) continue;
      const std::int64_t f = fine.at(i, j);
      bool uniform = a.c[f] > 0;
      for (int dj = -1; dj <= 1 && uniform; ++dj)
        for (int di = -1; di <= 1 && uniform; ++di) uniform = same(fine.at(i + di, j + dj), f);
      if (uniform) found = f;
    }
  if (found < 0) return std::nullopt;
  const Stencil9Row<Real> r{a.c[found], a.e[found], a.n[found], a.ne[found], a.nw[found]};
  UniformRegion<Real> region;
  const GridShape small{8, 8};
  std::vector<Real> filled[5];
  const Real values[5] = {r.c, r.e, r.n, r.ne, r.nw};
  for (int k = 0; k < 5; ++k) filled[k].assign(small.padded_size(), values[k]);
  const Stencil9ViewOf<Real> sa{filled[0].data(), filled[1].data(), filled[2].data(), filled[3].data(),
                                filled[4].data()};
  uniform_results(
      region,
      [&](GridShape g, InterpolationArraysOf<Real> p) {
        build_interpolation(g, LumpedStencil9Operator<Real>{{sa, g.stride()}}, p, Execution::serial);
      },
      [&](GridShape g, InterpolationViewOf<Real> p, Stencil9ArraysOf<Real> out) {
        galerkin(g, Stencil9Entries<Real>{sa, g.stride()}, p, out, Execution::serial);
      });
  region.windows = detail::uniform_windows(
      fine,
      [a, r](std::int64_t f) {
        return (a.c[f] == r.c) & (a.e[f] == r.e) & (a.n[f] == r.n) & (a.ne[f] == r.ne) & (a.nw[f] == r.nw);
      },
      execution);
  return region;
}

// The Galerkin product alone: which weights are the uniform ones is read off the weights.
template <class Entries, class Real>
void galerkin_checking_weights(GridShape fine, const Entries& a, InterpolationViewOf<Real> p,
                               Stencil9ArraysOf<Real> out, Execution execution, const UniformRegion<Real>* uniform) {
  std::vector<std::uint8_t> uniform_weights;
  if (uniform) uniform_weights = weights_equal(fine.coarser(), p, uniform->weights, execution);
  galerkin(fine, a, p, out, execution, uniform, uniform ? uniform_weights.data() : nullptr);
}

// Interpolation, then the Galerkin product, from one uniform-region analysis: the
// interpolation has just written the uniform weights wherever a coarse node's window is
// uniform, so the windows mark (some of) the nodes with uniform weights.
template <class Operator, class Entries, class Real>
void coarsen(GridShape fine, const Operator& op, const Entries& a, InterpolationArraysOf<Real> p,
             Stencil9ArraysOf<Real> out, Execution execution, const UniformRegion<Real>* uniform) {
  build_interpolation(fine, op, p, execution, uniform);
  galerkin(fine, a, p.view(), out, execution, uniform, uniform ? uniform->windows.data() : nullptr);
}

}  // namespace

void build_interpolation_texels(GridShape fine, const std::uint8_t* bits, InterpolationArrays p, Execution execution) {
  const auto uniform = uniform_texel_region<double>(fine, bits, execution);
  build_interpolation(fine, TexelOperator{bits}, p, execution, &uniform);
}
void build_interpolation_stencil9(GridShape fine, Stencil9View a, InterpolationArrays p, Execution execution) {
  const auto uniform = uniform_stencil9_region(fine, a, execution);
  build_interpolation(fine, LumpedStencil9Operator<double>{{a, fine.stride()}}, p, execution,
                      uniform ? &*uniform : nullptr);
}
void build_interpolation_texels(GridShape fine, const std::uint8_t* bits, InterpolationArraysFloat p,
                                Execution execution) {
  const auto uniform = uniform_texel_region<float>(fine, bits, execution);
  build_interpolation(fine, TexelOperator{bits}, p, execution, &uniform);
}
void build_interpolation_stencil9(GridShape fine, Stencil9ViewFloat a, InterpolationArraysFloat p,
                                  Execution execution) {
  const auto uniform = uniform_stencil9_region(fine, a, execution);
  build_interpolation(fine, LumpedStencil9Operator<float>{{a, fine.stride()}}, p, execution,
                      uniform ? &*uniform : nullptr);
}
void galerkin_texels(GridShape fine, const std::uint8_t* bits, InterpolationView p, Stencil9Arrays coarse_a,
                     Execution execution) {
  const auto uniform = uniform_texel_region<double>(fine, bits, execution);
  galerkin_checking_weights(fine, TexelEntries{bits}, p, coarse_a, execution, &uniform);
}
void galerkin_stencil9(GridShape fine, Stencil9View a, InterpolationView p, Stencil9Arrays coarse_a,
                       Execution execution) {
  const auto uniform = uniform_stencil9_region(fine, a, execution);
  galerkin_checking_weights(fine, Stencil9Entries<double>{a, fine.stride()}, p, coarse_a, execution,
                            uniform ? &*uniform : nullptr);
}
void galerkin_texels(GridShape fine, const std::uint8_t* bits, InterpolationViewFloat p,
                     Stencil9ArraysFloat coarse_a, Execution execution) {
  const auto uniform = uniform_texel_region<float>(fine, bits, execution);
  galerkin_checking_weights(fine, TexelEntries{bits}, p, coarse_a, execution, &uniform);
}
void galerkin_stencil9(GridShape fine, Stencil9ViewFloat a, InterpolationViewFloat p, Stencil9ArraysFloat coarse_a,
                       Execution execution) {
  const auto uniform = uniform_stencil9_region(fine, a, execution);
  galerkin_checking_weights(fine, Stencil9Entries<float>{a, fine.stride()}, p, coarse_a, execution,
                            uniform ? &*uniform : nullptr);
}

namespace {
// One region analysis per level, then interpolation and Galerkin operator (coarsen_* below).
template <class Real>
void coarsen_texels_as(GridShape fine, const std::uint8_t* bits, InterpolationArraysOf<Real> p,
                       Stencil9ArraysOf<Real> coarse_a, Execution execution) {
  const auto uniform = uniform_texel_region<Real>(fine, bits, execution);
  coarsen(fine, TexelOperator{bits}, TexelEntries{bits}, p, coarse_a, execution, &uniform);
}
template <class Real>
void coarsen_stencil9_as(GridShape fine, Stencil9ViewOf<Real> a, InterpolationArraysOf<Real> p,
                         Stencil9ArraysOf<Real> coarse_a, Execution execution) {
  const auto uniform = uniform_stencil9_region(fine, a, execution);
  coarsen(fine, LumpedStencil9Operator<Real>{{a, fine.stride()}}, Stencil9Entries<Real>{a, fine.stride()}, p,
          coarse_a, execution, uniform ? &*uniform : nullptr);
}
}  // namespace

void coarsen_texels(GridShape fine, const std::uint8_t* bits, InterpolationArrays p, Stencil9Arrays coarse_a,
                    Execution execution) {
  coarsen_texels_as<double>(fine, bits, p, coarse_a, execution);
}
void coarsen_stencil9(GridShape fine, Stencil9View a, InterpolationArrays p, Stencil9Arrays coarse_a,
                      Execution execution) {
  coarsen_stencil9_as<double>(fine, a, p, coarse_a, execution);
}
void coarsen_texels(GridShape fine, const std::uint8_t* bits, InterpolationArraysFloat p, Stencil9ArraysFloat coarse_a,
                    Execution execution) {
  coarsen_texels_as<float>(fine, bits, p, coarse_a, execution);
}
void coarsen_stencil9(GridShape fine, Stencil9ViewFloat a, InterpolationArraysFloat p, Stencil9ArraysFloat coarse_a,
                      Execution execution) {
  coarsen_stencil9_as<float>(fine, a, p, coarse_a, execution);
}

void build_interpolation_texels_reference(GridShape fine, const std::uint8_t* bits, InterpolationArrays p) {
  build_interpolation(fine, TexelOperator{bits}, p, Execution::serial);
}
void build_interpolation_stencil9_reference(GridShape fine, Stencil9View a, InterpolationArrays p) {
  build_interpolation(fine, LumpedStencil9Operator<double>{{a, fine.stride()}}, p, Execution::serial);
}
void galerkin_texels_reference(GridShape fine, const std::uint8_t* bits, InterpolationView p, Stencil9Arrays coarse_a) {
  galerkin(fine, TexelEntries{bits}, p, coarse_a, Execution::serial);
}
void galerkin_stencil9_reference(GridShape fine, Stencil9View a, InterpolationView p, Stencil9Arrays coarse_a) {
  galerkin(fine, Stencil9Entries<double>{a, fine.stride()}, p, coarse_a, Execution::serial);
}
void build_interpolation_texels_reference(GridShape fine, const std::uint8_t* bits, InterpolationArraysFloat p) {
  build_interpolation(fine, TexelOperator{bits}, p, Execution::serial);
}
void build_interpolation_stencil9_reference(GridShape fine, Stencil9ViewFloat a, InterpolationArraysFloat p) {
  build_interpolation(fine, LumpedStencil9Operator<float>{{a, fine.stride()}}, p, Execution::serial);
}
void galerkin_texels_reference(GridShape fine, const std::uint8_t* bits, InterpolationViewFloat p,
                               Stencil9ArraysFloat coarse_a) {
  galerkin(fine, TexelEntries{bits}, p, coarse_a, Execution::serial);
}
void galerkin_stencil9_reference(GridShape fine, Stencil9ViewFloat a, InterpolationViewFloat p,
                                 Stencil9ArraysFloat coarse_a) {
  galerkin(fine, Stencil9Entries<float>{a, fine.stride()}, p, coarse_a, Execution::serial);
}

}  // namespace dgtex::kernels
