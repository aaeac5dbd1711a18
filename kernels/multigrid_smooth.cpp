#include "dgtex/kernels/multigrid_smooth.h"

#include "dgtex/kernels/multigrid_unknowns.h"

#include <algorithm>

#include "multigrid_lagged_rows.h"

namespace dgtex::kernels {
namespace {

// 1 / degree, indexed by the degree bits; computed as 1.0 / d like the reference does.
constexpr double inverse_degree[8] = {0.0, 1.0, 1.0 / 2.0, 1.0 / 3.0, 1.0 / 4.0, 0.0, 0.0, 0.0};

// Sum over the eight off-diagonal couplings of a 9-point stencil times x, in a fixed order.
template <class Real>
inline Real stencil9_offdiagonal(const Stencil9ViewOf<Real>& a, const Real* x, std::int64_t t, std::int64_t s) {
  return a.e[t - 1] * x[t - 1] + a.e[t] * x[t + 1] + a.n[t - s] * x[t - s] + a.n[t] * x[t + s] +
         a.ne[t - s - 1] * x[t - s - 1] + a.nw[t - s + 1] * x[t - s + 1] + a.nw[t] * x[t + s - 1] +
         a.ne[t] * x[t + s + 1];
}

// One colour of the texel level on row j.
inline void texel_row(GridShape shape, const std::uint8_t* bits, const double* b, double* x, int j, int color) {
  const std::int64_t s = shape.stride();
  const std::int64_t row = shape.at(0, j);
  for (int i = (color + j) & 1; i < shape.nx; i += 2) {
    const std::int64_t t = row + i;
    const std::uint8_t m = bits[t];
    const double sum = b[t] + ((m & couples_west_unknown) ? x[t - 1] : 0.0) +
                       ((m & couples_east_unknown) ? x[t + 1] : 0.0) +
                       ((m & couples_south_unknown) ? x[t - s] : 0.0) +
                       ((m & couples_north_unknown) ? x[t + s] : 0.0);
    if (m & is_unknown) x[t] = sum * inverse_degree[laplace_degree(m)];
  }
}

// One colour (i % 2 == ci) of a 9-point level on row j.
template <class Real>
inline void stencil9_row(GridShape shape, const Stencil9ViewOf<Real>& a, const Real* b, Real* x, int j, int ci) {
  const std::int64_t s = shape.stride();
  const std::int64_t row = shape.at(0, j);
  for (int i = ci; i < shape.nx; i += 2) {
    const std::int64_t t = row + i;
    if (a.c[t] > 0) x[t] = (b[t] - stencil9_offdiagonal(a, x, t, s)) / a.c[t];
  }
}

using detail::lagged_rows;

}  // namespace

namespace {

inline void cg_update_row(GridShape shape, double alpha, const double* p, const double* q, double* x, double* r,
                          double* row_norm2, int j) {
  const std::int64_t row = shape.at(0, j);
  double norm2 = 0;
  for (int i = 0; i < shape.nx; ++i) {
    x[row + i] += alpha * p[row + i];
    r[row + i] -= alpha * q[row + i];
    norm2 += r[row + i] * r[row + i];
  }
  row_norm2[j] = norm2;
}

inline void red_from_zero_row(GridShape shape, const std::uint8_t* bits, const double* b, double* x, int j) {
  const std::int64_t row = shape.at(0, j);
  for (int i = 0; i < shape.nx; ++i) {
    const std::int64_t t = row + i;
    const std::uint8_t m = bits[t];
    x[t] = ((m & is_unknown) && ((i + j) & 1) == 0) ? b[t] * inverse_degree[laplace_degree(m)] : 0.0;
  }
}

}  // namespace

void smooth_texels_sweep(GridShape shape, const std::uint8_t* bits, const double* b, double* x, bool forward,
                         Execution execution, double* row_dot) {
  const int first = forward ? 0 : 1, second = 1 - first;
  lagged_rows(
      shape.ny, [&](int j) { texel_row(shape, bits, b, x, j, first); },
      [&](int j) {
        texel_row(shape, bits, b, x, j, second);
        if (!row_dot) return;
        const std::int64_t row = shape.at(0, j);  // row j is final now
        double dot = 0;
        for (int i = 0; i < shape.nx; ++i) dot += b[row + i] * x[row + i];
        row_dot[j] = dot;
      },
      execution);
}

void smooth_texels_sweep_from_zero(GridShape shape, const std::uint8_t* bits, const double* b, double* x,
                                   Execution execution) {
  lagged_rows(
      shape.ny, [&](int j) { red_from_zero_row(shape, bits, b, x, j); },
      [&](int j) { texel_row(shape, bits, b, x, j, 1); }, execution);
}

void cg_update_and_smooth_texels_from_zero(GridShape shape, const std::uint8_t* bits, double alpha, const double* p,
                                           const double* q, double* x, double* r, double* z, double* row_norm2,
                                           Execution execution) {
  lagged_rows(
      shape.ny,
      [&](int j) {
        cg_update_row(shape, alpha, p, q, x, r, row_norm2, j);
        red_from_zero_row(shape, bits, r, z, j);
      },
      [&](int j) { texel_row(shape, bits, r, z, j, 1); }, execution);
}

void cg_update_and_smooth_texels_from_zero_reference(GridShape shape, const std::uint8_t* bits, double alpha,
                                                     const double* p, const double* q, double* x, double* r, double* z,
                                                     double* row_norm2) {
  for (int j = 0; j < shape.ny; ++j) cg_update_row(shape, alpha, p, q, x, r, row_norm2, j);
  for (int j = 0; j < shape.ny; ++j)
    for (int i = 0; i < shape.nx; ++i) z[shape.at(i, j)] = 0.0;
  smooth_texels_color_reference(shape, bits, r, z, 0);
  smooth_texels_color_reference(shape, bits, r, z, 1);
}

namespace {
template <class Real>
void stencil9_sweep(GridShape shape, Stencil9ViewOf<Real> a, const Real* b, Real* x, bool forward,
                    Execution execution) {
  // Colour (ci, cj) = (i % 2, j % 2), numbered ci + 2 cj: colours 0, 1 live on even rows, 2, 3
  // on odd rows, and nodes of one row depend on the other parity's rows only through j +- 1.
  const int first_parity = forward ? 0 : 1;
  auto phase = [&](int j, bool first_phase) {
    if ((j & 1) != (first_phase ? first_parity : 1 - first_parity)) return;
    if (forward) {
      stencil9_row(shape, a, b, x, j, 0);
      stencil9_row(shape, a, b, x, j, 1);
    } else {
      stencil9_row(shape, a, b, x, j, 1);
      stencil9_row(shape, a, b, x, j, 0);
    }
  };
  lagged_rows(
      shape.ny, [&](int j) { phase(j, true); }, [&](int j) { phase(j, false); }, execution);
}
}  // namespace

void smooth_stencil9_sweep(GridShape shape, Stencil9View a, const double* b, double* x, bool forward,
                           Execution execution) {
  stencil9_sweep(shape, a, b, x, forward, execution);
}
void smooth_stencil9_sweep(GridShape shape, Stencil9ViewFloat a, const float* b, float* x, bool forward,
                           Execution execution) {
  stencil9_sweep(shape, a, b, x, forward, execution);
}

void smooth_texels_color(GridShape shape, const std::uint8_t* bits, const double* b, double* x, int color,
                         Execution execution) {
  forall(
      shape.ny, [&](std::int64_t j) { texel_row(shape, bits, b, x, static_cast<int>(j), color); }, execution);
}

void smooth_texels_color_reference(GridShape shape, const std::uint8_t* bits, const double* b, double* x, int color) {
  for (int j = 0; j < shape.ny; ++j)
    for (int i = 0; i < shape.nx; ++i) {
      if ((i + j) % 2 != color) continue;
      const std::int64_t t = shape.at(i, j);
      if (!(bits[t] & is_unknown)) continue;
      double sum = b[t];
      sum += (bits[t] & couples_west_unknown) ? x[shape.at(i - 1, j)] : 0.0;
      sum += (bits[t] & couples_east_unknown) ? x[shape.at(i + 1, j)] : 0.0;
      sum += (bits[t] & couples_south_unknown) ? x[shape.at(i, j - 1)] : 0.0;
      sum += (bits[t] & couples_north_unknown) ? x[shape.at(i, j + 1)] : 0.0;
      x[t] = sum * (1.0 / laplace_degree(bits[t]));
    }
}

void smooth_stencil9_color(GridShape shape, Stencil9View a, const double* b, double* x, int color, Execution execution) {
  const std::int64_t s = shape.stride();
  const int ci = color & 1, cj = color >> 1;
  const int rows = (shape.ny - cj + 1) / 2;
  forall(
      rows,
      [&](std::int64_t r) {
        const int j = static_cast<int>(2 * r + cj);
        const std::int64_t row = shape.at(0, j);
        for (int i = ci; i < shape.nx; i += 2) {
          const std::int64_t t = row + i;
          if (a.c[t] > 0) x[t] = (b[t] - stencil9_offdiagonal(a, x, t, s)) / a.c[t];
        }
      },
      execution);
}

namespace {
template <class Real>
void stencil9_color_reference(GridShape shape, Stencil9ViewOf<Real> a, const Real* b, Real* x, int color) {
  const std::int64_t s = shape.stride();
  for (int j = 0; j < shape.ny; ++j)
    for (int i = 0; i < shape.nx; ++i) {
      if ((i % 2) + 2 * (j % 2) != color) continue;
      const std::int64_t t = shape.at(i, j);
      if (!(a.c[t] > 0)) continue;
      const Real offdiagonal = a.e[t - 1] * x[t - 1] + a.e[t] * x[t + 1] + a.n[t - s] * x[t - s] +
                                 a.n[t] * x[t + s] + a.ne[t - s - 1] * x[t - s - 1] +
                                 a.nw[t - s + 1] * x[t - s + 1] + a.nw[t] * x[t + s - 1] + a.ne[t] * x[t + s + 1];
      x[t] = (b[t] - offdiagonal) / a.c[t];
    }
}
}  // namespace

void smooth_stencil9_color_reference(GridShape shape, Stencil9View a, const double* b, double* x, int color) {
  stencil9_color_reference(shape, a, b, x, color);
}
void smooth_stencil9_color_reference(GridShape shape, Stencil9ViewFloat a, const float* b, float* x, int color) {
  stencil9_color_reference(shape, a, b, x, color);
}

}  // namespace dgtex::kernels
