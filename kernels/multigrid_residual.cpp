#include "dgtex/kernels/multigrid_residual.h"

#include "dgtex/kernels/multigrid_unknowns.h"
#include "multigrid_lagged_rows.h"

#include <vector>

#include "dgtex/kernels/multigrid_transfer.h"

namespace dgtex::kernels {
namespace {

// (A x)(t) for the 5-point texel operator: degree * x(t) minus the coupled unknown neighbours.
inline double texel_operator(std::uint8_t m, const double* x, std::int64_t t, std::int64_t s) {
  return laplace_degree(m) * x[t] - ((m & couples_west_unknown) ? x[t - 1] : 0.0) -
         ((m & couples_east_unknown) ? x[t + 1] : 0.0) - ((m & couples_south_unknown) ? x[t - s] : 0.0) -
         ((m & couples_north_unknown) ? x[t + s] : 0.0);
}

template <class Real>
inline Real stencil9_operator(const Stencil9ViewOf<Real>& a, const Real* x, std::int64_t t, std::int64_t s) {
  return a.c[t] * x[t] + a.e[t - 1] * x[t - 1] + a.e[t] * x[t + 1] + a.n[t - s] * x[t - s] + a.n[t] * x[t + s] +
         a.ne[t - s - 1] * x[t - s - 1] + a.nw[t - s + 1] * x[t - s + 1] + a.nw[t] * x[t + s - 1] +
         a.ne[t] * x[t + s + 1];
}

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
  const std::int64_t s = shape.stride();
  forall(
      shape.ny,
      [&](std::int64_t j) {
        const std::int64_t row = shape.at(0, static_cast<int>(j));
        double norm2 = 0;
        for (int i = 0; i < shape.nx; ++i) {
          const std::int64_t t = row + i;
          const std::uint8_t m = bits[t];
          const double value = (m & is_unknown) ? b[t] - texel_operator(m, x, t, s) : 0.0;
          r[t] = value;
          norm2 += value * value;
        }
        if (row_norm2) row_norm2[j] = norm2;
      },
      execution);
}

void residual_texels_reference(GridShape shape, const std::uint8_t* bits, const double* b, const double* x, double* r,
                               double* row_norm2) {
  for (int j = 0; j < shape.ny; ++j) {
    double norm2 = 0;
    for (int i = 0; i < shape.nx; ++i) {
      const std::int64_t t = shape.at(i, j);
      const double value = reference_texel_residual(shape, bits, b, x, i, j);
      r[t] = value;
      norm2 += value * value;
    }
    if (row_norm2) row_norm2[j] = norm2;
  }
}

void residual_texels_color(GridShape shape, const std::uint8_t* bits, const double* b, const double* x, double* r,
                           int color, Execution execution) {
  const std::int64_t s = shape.stride();
  forall(
      shape.ny,
      [&](std::int64_t j) {
        const std::int64_t row = shape.at(0, static_cast<int>(j));
        for (int i = static_cast<int>((color + j) & 1); i < shape.nx; i += 2) {
          const std::int64_t t = row + i;
          const std::uint8_t m = bits[t];
          r[t] = (m & is_unknown) ? b[t] - texel_operator(m, x, t, s) : 0.0;
        }
      },
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
  const std::int64_t s = fine.stride(), cs = coarse.stride();
  // The red residual at fine node t; 0 at nodes without unknown, ghosts included (their bits
  // are 0), as residual_texels_color leaves them in r.
  auto red_residual = [&](std::int64_t t) {
    const std::uint8_t m = bits[t];
    return (m & is_unknown) ? b[t] - texel_operator(m, x, t, s) : 0.0;
  };
  forall(
      coarse.ny,
      [&](std::int64_t J64) {
        const int J = static_cast<int>(J64);
        const std::int64_t row = coarse.at(0, J), f0 = fine.at(0, 2 * J);
        // Cell centres (2I - 1, 2J +- 1) of I = 0: the ghost column.
        double west_north = red_residual(f0 + s - 1), west_south = red_residual(f0 - s - 1);
        for (int I = 0; I < coarse.nx; ++I) {
          const std::int64_t c = row + I, f = f0 + 2 * I;
          const double east_north = red_residual(f + s + 1), east_south = red_residual(f - s + 1);
          b_coarse[c] = static_cast<Real>(red_residual(f) + p.sw[c] * east_north + p.se[c - 1] * west_north +
                                          p.nw[c - cs] * east_south + p.ne[c - cs - 1] * west_south);
          west_north = east_north;
          west_south = east_south;
        }
      },
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
  const std::int64_t s = shape.stride();
  forall(
      shape.ny,
      [&](std::int64_t j) {
        const std::int64_t row = shape.at(0, static_cast<int>(j));
        double norm2 = 0;
        for (int i = 0; i < shape.nx; ++i) {
          const std::int64_t t = row + i;
          const Real value = a.c[t] > 0 ? b[t] - stencil9_operator(a, x, t, s) : Real(0);
          r[t] = value;
          norm2 += static_cast<double>(value) * value;
        }
        if (row_norm2) row_norm2[j] = norm2;
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
  const std::int64_t s = shape.stride();
  forall(
      shape.ny,
      [&](std::int64_t j) {
        const std::int64_t row = shape.at(0, static_cast<int>(j));
        double dot = 0;
        for (int i = 0; i < shape.nx; ++i) {
          const std::int64_t t = row + i;
          const std::uint8_t m = bits[t];
          const double value = (m & is_unknown) ? texel_operator(m, x, t, s) : 0.0;
          y[t] = value;
          dot += value * x[t];
        }
        if (row_dot) row_dot[j] = dot;
      },
      execution);
}

void update_direction_and_apply_texels(GridShape shape, const std::uint8_t* bits, const double* z, double beta,
                                       double* p, double* q, double* row_dot, Execution execution) {
  const std::int64_t s = shape.stride();
  detail::lagged_rows(
      shape.ny,
      [&](int j) {
        const std::int64_t row = shape.at(0, j);
        for (int i = 0; i < shape.nx; ++i) p[row + i] = z[row + i] + beta * p[row + i];
      },
      [&](int j) {
        const std::int64_t row = shape.at(0, j);
        double dot = 0;
        for (int i = 0; i < shape.nx; ++i) {
          const std::int64_t t = row + i;
          const std::uint8_t m = bits[t];
          const double value = (m & is_unknown) ? texel_operator(m, p, t, s) : 0.0;
          q[t] = value;
          dot += value * p[t];
        }
        row_dot[j] = dot;
      },
      execution);
}

void update_direction_and_apply_texels_reference(GridShape shape, const std::uint8_t* bits, const double* z,
                                                 double beta, double* p, double* q, double* row_dot) {
  for (int j = 0; j < shape.ny; ++j)
    for (int i = 0; i < shape.nx; ++i) p[shape.at(i, j)] = z[shape.at(i, j)] + beta * p[shape.at(i, j)];
  apply_texels(shape, bits, p, q, row_dot, Execution::serial);
}

}  // namespace dgtex::kernels
