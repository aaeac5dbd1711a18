#include "dgtex/kernels/multigrid_galerkin.h"

#include "dgtex/kernels/multigrid_unknowns.h"

namespace dgtex::kernels {
namespace {

// Entry A(t, t + dx + dy * stride) of the level-0 texel operator (dx, dy in -1..1).
struct TexelOperator {
  const std::uint8_t* bits;
  std::int64_t s;
  double operator()(std::int64_t t, int dx, int dy) const {
    const std::uint8_t m = bits[t];
    if (dx == 0 && dy == 0) return (m & is_unknown) ? laplace_degree(m) : 0.0;
    if (dy == 0) return (m & (dx < 0 ? couples_west_unknown : couples_east_unknown)) ? -1.0 : 0.0;
    if (dx == 0) return (m & (dy < 0 ? couples_south_unknown : couples_north_unknown)) ? -1.0 : 0.0;
    return 0.0;
  }
};

// Entry of a symmetric 9-point operator (multigrid_grid.h).
struct Stencil9Operator {
  Stencil9View a;
  std::int64_t s;
  double operator()(std::int64_t t, int dx, int dy) const {
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

// A weight -numerator / denominator, or 0 where the denominator vanishes (a node that is
// no unknown, or one coupled only across the collapsed direction: no coarse representation).
inline double weight(double numerator, double denominator, double diagonal) {
  return (diagonal > 0 && denominator > 1e-12 * diagonal) ? -numerator / denominator : 0.0;
}

template <class Operator>
void build_interpolation(GridShape fine, const Operator& a, InterpolationArrays p, Execution execution) {
  const GridShape coarse = fine.coarser();
  const std::int64_t cs = coarse.stride();
  // Pass 1: fine nodes on coarse grid lines, from the stencil collapsed across the line.
  forall(
      coarse.ny,
      [&](std::int64_t J64) {
        const int J = static_cast<int>(J64);
        for (int I = 0; I < coarse.nx; ++I) {
          const std::int64_t c = coarse.at(I, J);
          p.xw[c] = p.xe[c] = p.ys[c] = p.yn[c] = 0.0;
          if (2 * I + 1 < fine.nx) {
            const std::int64_t f = fine.at(2 * I + 1, 2 * J);
            const double west = a(f, -1, -1) + a(f, -1, 0) + a(f, -1, 1);
            const double east = a(f, 1, -1) + a(f, 1, 0) + a(f, 1, 1);
            const double centre = a(f, 0, -1) + a(f, 0, 0) + a(f, 0, 1);
            p.xw[c] = weight(west, centre, a(f, 0, 0));
            p.xe[c] = weight(east, centre, a(f, 0, 0));
          }
          if (2 * J + 1 < fine.ny) {
            const std::int64_t f = fine.at(2 * I, 2 * J + 1);
            const double south = a(f, -1, -1) + a(f, 0, -1) + a(f, 1, -1);
            const double north = a(f, -1, 1) + a(f, 0, 1) + a(f, 1, 1);
            const double centre = a(f, -1, 0) + a(f, 0, 0) + a(f, 1, 0);
            p.ys[c] = weight(south, centre, a(f, 0, 0));
            p.yn[c] = weight(north, centre, a(f, 0, 0));
          }
        }
      },
      execution);
  // Pass 2: cell-centre fine nodes, from their full stencil and the pass-1 weights.
  forall(
      coarse.ny,
      [&](std::int64_t J64) {
        const int J = static_cast<int>(J64);
        for (int I = 0; I < coarse.nx; ++I) {
          const std::int64_t c = coarse.at(I, J);
          p.sw[c] = p.se[c] = p.nw[c] = p.ne[c] = 0.0;
          if (2 * I + 1 >= fine.nx || 2 * J + 1 >= fine.ny) continue;
          const std::int64_t f = fine.at(2 * I + 1, 2 * J + 1);
          const double d = a(f, 0, 0);
          if (!(d > 0)) continue;
          const double as = a(f, 0, -1), an = a(f, 0, 1), aw = a(f, -1, 0), ae = a(f, 1, 0);
          p.sw[c] = -(a(f, -1, -1) + as * p.xw[c] + aw * p.ys[c]) / d;
          p.se[c] = -(a(f, 1, -1) + as * p.xe[c] + ae * p.ys[c + 1]) / d;
          p.nw[c] = -(a(f, -1, 1) + an * p.xw[c + cs] + aw * p.yn[c]) / d;
          p.ne[c] = -(a(f, 1, 1) + an * p.xe[c + cs] + ae * p.yn[c + 1]) / d;
        }
      },
      execution);
}

// Interpolation weights of fine node (i, j) (parity-dependent): up to four coarse
// neighbours as offsets (dI, dJ) from (i >> 1, j >> 1) and weights. Returns the count.
inline int interpolation_of(GridShape coarse, const InterpolationView& p, int i, int j, int* dI, int* dJ, double* w) {
  const std::int64_t c = coarse.at(i >> 1, j >> 1);
  switch ((i & 1) + 2 * (j & 1)) {
    case 0: dI[0] = 0; dJ[0] = 0; w[0] = 1.0; return 1;
    case 1: dI[0] = 0; dJ[0] = 0; w[0] = p.xw[c]; dI[1] = 1; dJ[1] = 0; w[1] = p.xe[c]; return 2;
    case 2: dI[0] = 0; dJ[0] = 0; w[0] = p.ys[c]; dI[1] = 0; dJ[1] = 1; w[1] = p.yn[c]; return 2;
    default:
      dI[0] = 0; dJ[0] = 0; w[0] = p.sw[c];
      dI[1] = 1; dJ[1] = 0; w[1] = p.se[c];
      dI[2] = 0; dJ[2] = 1; w[2] = p.nw[c];
      dI[3] = 1; dJ[3] = 1; w[3] = p.ne[c];
      return 4;
  }
}

template <class Operator>
void galerkin(GridShape fine, const Operator& a, InterpolationView p, Stencil9Arrays out, Execution execution) {
  const GridShape coarse = fine.coarser();
  const std::int64_t cs = coarse.stride();
  forall(
      coarse.ny,
      [&](std::int64_t J64) {
        const int J = static_cast<int>(J64);
        for (int I = 0; I < coarse.nx; ++I) {
          const std::int64_t c = coarse.at(I, J);
          // P(f, C) for the fine nodes f = (2I + di, 2J + dj) around coarse node C.
          const double column[3][3] = {
              {p.ne[c - cs - 1], p.yn[c - cs], p.nw[c - cs]},  // dj = -1: di = -1, 0, 1
              {p.xe[c - 1], 1.0, p.xw[c]},                      // dj = 0
              {p.se[c - 1], p.ys[c], p.sw[c]},                  // dj = 1
          };
          double acc[3][3] = {};  // acc[dJ + 1][dI + 1]: coupling to coarse (I + dI, J + dJ)
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
              const int fi = 2 * I + di, fj = 2 * J + dj;
              if (fi < 0 || fj < 0 || fi >= fine.nx || fj >= fine.ny) continue;
              const double pfc = column[dj + 1][di + 1];
              if (pfc == 0.0) continue;
              const std::int64_t f = fine.at(fi, fj);
              for (int oy = -1; oy <= 1; ++oy)
                for (int ox = -1; ox <= 1; ++ox) {
                  const double afg = a(f, ox, oy);
                  if (afg == 0.0) continue;
                  const int gi = fi + ox, gj = fj + oy;
                  int dI[4], dJ[4];
                  double w[4];
                  const int count = interpolation_of(coarse, p, gi, gj, dI, dJ, w);
                  for (int k = 0; k < count; ++k) {
                    const int DI = (gi >> 1) + dI[k] - I, DJ = (gj >> 1) + dJ[k] - J;
                    acc[DJ + 1][DI + 1] += pfc * afg * w[k];
                  }
                }
            }
          out.c[c] = acc[1][1];
          out.e[c] = acc[1][2];
          out.n[c] = acc[2][1];
          out.ne[c] = acc[2][2];
          out.nw[c] = acc[2][0];
        }
      },
      execution);
}

}  // namespace

void build_interpolation_texels(GridShape fine, const std::uint8_t* bits, InterpolationArrays p, Execution execution) {
  build_interpolation(fine, TexelOperator{bits, fine.stride()}, p, execution);
}
void build_interpolation_stencil9(GridShape fine, Stencil9View a, InterpolationArrays p, Execution execution) {
  build_interpolation(fine, Stencil9Operator{a, fine.stride()}, p, execution);
}
void galerkin_texels(GridShape fine, const std::uint8_t* bits, InterpolationView p, Stencil9Arrays coarse_a,
                     Execution execution) {
  galerkin(fine, TexelOperator{bits, fine.stride()}, p, coarse_a, execution);
}
void galerkin_stencil9(GridShape fine, Stencil9View a, InterpolationView p, Stencil9Arrays coarse_a,
                       Execution execution) {
  galerkin(fine, Stencil9Operator{a, fine.stride()}, p, coarse_a, execution);
}

}  // namespace dgtex::kernels
