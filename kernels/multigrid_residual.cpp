#include "dgtex/kernels/multigrid_residual.h"

#include "dgtex/kernels/multigrid_unknowns.h"
#include "multigrid_lagged_rows.h"

namespace dgtex::kernels {
namespace {

// (A x)(t) for the 5-point texel operator: degree * x(t) minus the coupled unknown neighbours.
inline double texel_operator(std::uint8_t m, const double* x, std::int64_t t, std::int64_t s) {
  return laplace_degree(m) * x[t] - ((m & couples_west_unknown) ? x[t - 1] : 0.0) -
         ((m & couples_east_unknown) ? x[t + 1] : 0.0) - ((m & couples_south_unknown) ? x[t - s] : 0.0) -
         ((m & couples_north_unknown) ? x[t + s] : 0.0);
}

inline double stencil9_operator(const Stencil9View& a, const double* x, std::int64_t t, std::int64_t s) {
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

void residual_stencil9(GridShape shape, Stencil9View a, const double* b, const double* x, double* r, double* row_norm2,
                       Execution execution) {
  const std::int64_t s = shape.stride();
  forall(
      shape.ny,
      [&](std::int64_t j) {
        const std::int64_t row = shape.at(0, static_cast<int>(j));
        double norm2 = 0;
        for (int i = 0; i < shape.nx; ++i) {
          const std::int64_t t = row + i;
          const double value = a.c[t] > 0 ? b[t] - stencil9_operator(a, x, t, s) : 0.0;
          r[t] = value;
          norm2 += value * value;
        }
        if (row_norm2) row_norm2[j] = norm2;
      },
      execution);
}

void residual_stencil9_reference(GridShape shape, Stencil9View a, const double* b, const double* x, double* r,
                                 double* row_norm2) {
  const std::int64_t s = shape.stride();
  for (int j = 0; j < shape.ny; ++j) {
    double norm2 = 0;
    for (int i = 0; i < shape.nx; ++i) {
      const std::int64_t t = shape.at(i, j);
      double value = 0;
      if (a.c[t] > 0) {
        const double ax = a.c[t] * x[t] + a.e[t - 1] * x[t - 1] + a.e[t] * x[t + 1] + a.n[t - s] * x[t - s] +
                          a.n[t] * x[t + s] + a.ne[t - s - 1] * x[t - s - 1] + a.nw[t - s + 1] * x[t - s + 1] +
                          a.nw[t] * x[t + s - 1] + a.ne[t] * x[t + s + 1];
        value = b[t] - ax;
      }
      r[t] = value;
      norm2 += value * value;
    }
    if (row_norm2) row_norm2[j] = norm2;
  }
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
