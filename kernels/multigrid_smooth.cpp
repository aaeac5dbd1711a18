#include "dgtex/kernels/multigrid_smooth.h"

#include "dgtex/kernels/multigrid_unknowns.h"

#include <algorithm>

#include "multigrid_lagged_rows.h"
#include "multigrid_rows.h"

namespace dgtex::kernels {

using detail::lagged_rows;
using detail::texel_rows;

void smooth_texels_sweep(GridShape shape, const std::uint8_t* bits, const double* b, double* x, bool forward,
                         Execution execution, double* row_dot) {
  const int first = forward ? 0 : 1, second = 1 - first;
  const detail::TexelRowKernels& rows = texel_rows();
  lagged_rows(
      shape.ny, [&](int j) { rows.smooth_color(shape, bits, b, x, j, first); },
      [&](int j) {
        rows.smooth_color(shape, bits, b, x, j, second);
        if (row_dot) row_dot[j] = rows.dot(shape, b, x, j);  // row j is final now
      },
      [&](int j) {
        rows.smooth_color_pair(shape, bits, b, x, j, first);
        if (row_dot) row_dot[j - 1] = rows.dot(shape, b, x, j - 1);
      },
      execution);
}

void smooth_texels_sweep_from_zero(GridShape shape, const std::uint8_t* bits, const double* b, double* x,
                                   Execution execution) {
  const detail::TexelRowKernels& rows = texel_rows();
  lagged_rows(
      shape.ny, [&](int j) { rows.red_from_zero(shape, bits, b, x, j); },
      [&](int j) { rows.smooth_color(shape, bits, b, x, j, 1); },
      [&](int j) { rows.red_from_zero_pair(shape, bits, b, x, j); }, execution);
}

void cg_update_and_smooth_texels_from_zero(GridShape shape, const std::uint8_t* bits, double alpha, const double* p,
                                           const double* q, double* x, double* r, double* z, double* row_norm2,
                                           Execution execution) {
  const detail::TexelRowKernels& rows = texel_rows();
  lagged_rows(
      shape.ny,
      [&](int j) {
        row_norm2[j] = rows.cg_update(shape, alpha, p, q, x, r, j);
        rows.red_from_zero(shape, bits, r, z, j);
      },
      [&](int j) { rows.smooth_color(shape, bits, r, z, j, 1); },
      [&](int j) {
        row_norm2[j] = rows.cg_update(shape, alpha, p, q, x, r, j);
        rows.red_from_zero_pair(shape, bits, r, z, j);
      },
      execution);
}

void cg_update_and_smooth_texels_from_zero_reference(GridShape shape, const std::uint8_t* bits, double alpha,
                                                     const double* p, const double* q, double* x, double* r, double* z,
                                                     double* row_norm2) {
  for (int j = 0; j < shape.ny; ++j) {
    detail::RowSum norm2;
    for (int i = 0; i < shape.nx; ++i) {
      const std::int64_t t = shape.at(i, j);
      x[t] += alpha * p[t];
      r[t] -= alpha * q[t];
      norm2.add(i, r[t] * r[t]);
    }
    row_norm2[j] = norm2.total();
  }
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
  const auto smooth_color = detail::stencil9_rows<Real>().smooth_color;
  auto phase = [&](int j, bool first_phase) {
    if ((j & 1) != (first_phase ? first_parity : 1 - first_parity)) return;
    smooth_color(shape, a, b, x, j, forward ? 0 : 1);
    smooth_color(shape, a, b, x, j, forward ? 1 : 0);
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
  const detail::TexelRowKernels& rows = texel_rows();
  forall(
      shape.ny, [&](std::int64_t j) { rows.smooth_color(shape, bits, b, x, static_cast<int>(j), color); }, execution);
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
  const int ci = color & 1, cj = color >> 1;
  const int rows = (shape.ny - cj + 1) / 2;
  const auto smooth_color = detail::stencil9_rows<double>().smooth_color;
  forall(
      rows, [&](std::int64_t r) { smooth_color(shape, a, b, x, static_cast<int>(2 * r + cj), ci); }, execution);
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
