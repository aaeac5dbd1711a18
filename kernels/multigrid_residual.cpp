#include "dgtex/kernels/multigrid_residual.h"

#include "dgtex/kernels/multigrid_unknowns.h"
#include "multigrid_lagged_rows.h"
#include "multigrid_rows.h"

#include <vector>

#include "dgtex/kernels/multigrid_transfer.h"

namespace dgtex::kernels {
namespace {

// (A x)(t) for the 5-point texel operator: degree * x(t) minus the coupled unknown neighbours.
using detail::texel_operator;
using detail::texel_rows;

// The plain form of b - A x at texel (i, j) (0 off the unknowns), for the references.
double reference_texel_residual(GridShape shape, const std::uint8_t* bits, const double* b, const double* x, int i,
                                int j) {
  const std::int64_t t = shape.at(i, j);
  if (!(bits[t] & is_unknown)) return 0;
  double ax = laplace_degree(bits[t]) * x[t];
  ax -= (bits[t] & couples_west_unknown) ? x[shape.at(i - 1, j)] : 0.0;
  ax -= (bits[t] & couples_east_unknown) ? x[shape.at(i + 1, j)] : 0.0;
  ax -= (bits[t] & couples_south_unknown) ? x[shape.at(i, j - 1)] : 0.0;
  ax -= (bits[t] & couples_north_unknown) ? x[shape.at(i, j + 1)] : 0.0;
  return b[t] - ax;
}

}  // namespace

void residual_texels(GridShape shape, const std::uint8_t* bits, const double* b, const double* x, double* r,
                     double* row_norm2, Execution execution) {
  const detail::TexelRowKernels& rows = texel_rows();
  forall(
      shape.ny,
      [&](std::int64_t j) {
        const double norm2 = rows.residual(shape, bits, b, x, r, static_cast<int>(j));
        if (row_norm2) row_norm2[j] = norm2;
      },
      execution);
}

void residual_texels_reference(GridShape shape, const std::uint8_t* bits, const double* b, const double* x, double* r,
                               double* row_norm2) {
  for (int j = 0; j < shape.ny; ++j) {
    detail::RowSum norm2;
    for (int i = 0; i < shape.nx; ++i) {
      const std::int64_t t = shape.at(i, j);
      const double value = reference_texel_residual(shape, bits, b, x, i, j);
      r[t] = value;
      norm2.add(i, value * value);
    }
    if (row_norm2) row_norm2[j] = norm2.total();
  }
}

void residual_texels_color(GridShape shape, const std::uint8_t* bits, const double* b, const double* x, double* r,
                           int color, Execution execution) {
  const detail::TexelRowKernels& rows = texel_rows();
  forall(
      shape.ny, [&](std::int64_t j) { rows.residual_color(shape, bits, b, x, r, static_cast<int>(j), color); },
      execution);
}

void residual_texels_color_reference(GridShape shape, const std::uint8_t* bits, const double* b, const double* x,
                                     double* r, int color) {
  for (int j = 0; j < shape.ny; ++j)
    for (int i = 0; i < shape.nx; ++i) {
      if ((i + j) % 2 != color) continue;
      const std::int64_t t = shape.at(i, j);
      const double value = reference_texel_residual(shape, bits, b, x, i, j);
      r[t] = value;
    }
}

namespace {
template <class Real>
void red_residual_texels_restricted(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p,
                                    const std::uint8_t* bits, const double* b, const double* x, Real* b_coarse,
                                    Execution execution) {
  const auto restricted_row = detail::texel_transfer_rows<Real>().red_residual_restricted;
  forall(
      coarse.ny,
      [&](std::int64_t J) { restricted_row(fine, coarse, p, bits, b, x, b_coarse, static_cast<int>(J)); },
      execution);
}
}  // namespace

void restrict_red_residual_texels(GridShape fine, GridShape coarse, InterpolationView p, const std::uint8_t* bits,
                                  const double* b, const double* x, double* b_coarse, Execution execution) {
  red_residual_texels_restricted(fine, coarse, p, bits, b, x, b_coarse, execution);
}
void restrict_red_residual_texels(GridShape fine, GridShape coarse, InterpolationViewFloat p, const std::uint8_t* bits,
                                  const double* b, const double* x, float* b_coarse, Execution execution) {
  red_residual_texels_restricted(fine, coarse, p, bits, b, x, b_coarse, execution);
}

void restrict_red_residual_texels_reference(GridShape fine, GridShape coarse, InterpolationView p,
                                            const std::uint8_t* bits, const double* b, const double* x,
                                            double* b_coarse) {
  std::vector<double> r(fine.padded_size(), 0.0);
  residual_texels_color_reference(fine, bits, b, x, r.data(), 0);
  restrict_red_residual_reference(fine, coarse, p, r.data(), b_coarse);
}
void restrict_red_residual_texels_reference(GridShape fine, GridShape coarse, InterpolationViewFloat p,
                                            const std::uint8_t* bits, const double* b, const double* x,
                                            float* b_coarse) {
  std::vector<double> r(fine.padded_size(), 0.0);
  residual_texels_color_reference(fine, bits, b, x, r.data(), 0);
  restrict_red_residual_reference(fine, coarse, p, r.data(), b_coarse);
}

namespace {
template <class Real>
void stencil9_residual(GridShape shape, Stencil9ViewOf<Real> a, const Real* b, const Real* x, Real* r,
                       double* row_norm2, Execution execution) {
  const auto residual_row = detail::stencil9_rows<Real>().residual;
  forall(
      shape.ny,
      [&](std::int64_t j) {
        residual_row(shape, a, b, x, r, static_cast<int>(j));
        if (!row_norm2) return;
        const std::int64_t row = shape.at(0, static_cast<int>(j));
        double norm2 = 0;
        for (int i = 0; i < shape.nx; ++i) norm2 += static_cast<double>(r[row + i]) * r[row + i];
        row_norm2[j] = norm2;
      },
      execution);
}

template <class Real>
void stencil9_residual_reference(GridShape shape, Stencil9ViewOf<Real> a, const Real* b, const Real* x, Real* r,
                                 double* row_norm2) {
  const std::int64_t s = shape.stride();
  for (int j = 0; j < shape.ny; ++j) {
    double norm2 = 0;
    for (int i = 0; i < shape.nx; ++i) {
      const std::int64_t t = shape.at(i, j);
      Real value = 0;
      if (a.c[t] > 0) {
        const Real ax = a.c[t] * x[t] + a.e[t - 1] * x[t - 1] + a.e[t] * x[t + 1] + a.n[t - s] * x[t - s] +
                          a.n[t] * x[t + s] + a.ne[t - s - 1] * x[t - s - 1] + a.nw[t - s + 1] * x[t - s + 1] +
                          a.nw[t] * x[t + s - 1] + a.ne[t] * x[t + s + 1];
        value = b[t] - ax;
      }
      r[t] = value;
      norm2 += static_cast<double>(value) * value;
    }
    if (row_norm2) row_norm2[j] = norm2;
  }
}
}  // namespace

void residual_stencil9(GridShape shape, Stencil9View a, const double* b, const double* x, double* r, double* row_norm2,
                       Execution execution) {
  stencil9_residual(shape, a, b, x, r, row_norm2, execution);
}
void residual_stencil9(GridShape shape, Stencil9ViewFloat a, const float* b, const float* x, float* r,
                       double* row_norm2, Execution execution) {
  stencil9_residual(shape, a, b, x, r, row_norm2, execution);
}
void residual_stencil9_reference(GridShape shape, Stencil9View a, const double* b, const double* x, double* r,
                                 double* row_norm2) {
  stencil9_residual_reference(shape, a, b, x, r, row_norm2);
}
void residual_stencil9_reference(GridShape shape, Stencil9ViewFloat a, const float* b, const float* x, float* r,
                                 double* row_norm2) {
  stencil9_residual_reference(shape, a, b, x, r, row_norm2);
}

void apply_texels(GridShape shape, const std::uint8_t* bits, const double* x, double* y, double* row_dot,
                  Execution execution) {
  const detail::TexelRowKernels& rows = texel_rows();
  forall(
      shape.ny,
      [&](std::int64_t j) {
        const double dot = rows.apply(shape, bits, x, y, static_cast<int>(j));
        if (row_dot) row_dot[j] = dot;
      },
      execution);
}

void apply_texels_at(GridShape shape, const std::uint8_t* bits, const double* x, const std::int64_t* texels,
                     std::int64_t count, double* y) {
  const std::int64_t s = shape.stride();
  for (std::int64_t m = 0; m < count; ++m) {
    const std::int64_t t = texels[m];
    y[t] = (bits[t] & is_unknown) ? detail::texel_operator(bits[t], x, t, s) : 0.0;
  }
}

void update_direction_and_apply_texels(GridShape shape, const std::uint8_t* bits, const double* z, double beta,
                                       double* p, double* q, double* row_dot, Execution execution) {
  const detail::TexelRowKernels& rows = texel_rows();
  detail::lagged_rows(
      shape.ny, [&](int j) { rows.direction(shape, z, beta, p, j); },
      [&](int j) { row_dot[j] = rows.apply(shape, bits, p, q, j); }, execution);
}

void update_direction_and_apply_texels_reference(GridShape shape, const std::uint8_t* bits, const double* z,
                                                 double beta, double* p, double* q, double* row_dot) {
  for (int j = 0; j < shape.ny; ++j)
    for (int i = 0; i < shape.nx; ++i) p[shape.at(i, j)] = z[shape.at(i, j)] + beta * p[shape.at(i, j)];
  for (int j = 0; j < shape.ny; ++j) {
    detail::RowSum dot;
    for (int i = 0; i < shape.nx; ++i) {
      const std::int64_t t = shape.at(i, j);
      q[t] = (bits[t] & is_unknown) ? texel_operator(bits[t], p, t, shape.stride()) : 0.0;
      dot.add(i, q[t] * p[t]);
    }
    row_dot[j] = dot.total();
  }
}

}  // namespace dgtex::kernels
