#include "dgtex/kernels/multigrid_transfer.h"

#include "multigrid_rows.h"

namespace dgtex::kernels {
namespace {

// P^T r at coarse node (I, J): its own fine node and the eight fine nodes around it.
template <class Real>
inline Real restricted(GridShape fine, GridShape coarse, const InterpolationViewOf<Real>& p, const Real* r, int I,
                       int J) {
  const std::int64_t c = coarse.at(I, J), cs = coarse.stride();
  const int i = 2 * I, j = 2 * J;
  return r[fine.at(i, j)] + p.xw[c] * r[fine.at(i + 1, j)] + p.xe[c - 1] * r[fine.at(i - 1, j)] +
         p.ys[c] * r[fine.at(i, j + 1)] + p.yn[c - cs] * r[fine.at(i, j - 1)] + p.sw[c] * r[fine.at(i + 1, j + 1)] +
         p.se[c - 1] * r[fine.at(i - 1, j + 1)] + p.nw[c - cs] * r[fine.at(i + 1, j - 1)] +
         p.ne[c - cs - 1] * r[fine.at(i - 1, j - 1)];
}

template <class Real>
void restrict_residual_rows(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p, const Real* r_fine,
                            Real* b_coarse, Execution execution) {
  forall(
      coarse.ny,
      [&](std::int64_t J) {
        const std::int64_t row = coarse.at(0, static_cast<int>(J));
        for (int I = 0; I < coarse.nx; ++I) b_coarse[row + I] = restricted(fine, coarse, p, r_fine, I, static_cast<int>(J));
      },
      execution);
}

template <class Real>
void restrict_residual_plain(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p, const Real* r_fine,
                             Real* b_coarse) {
  for (int J = 0; J < coarse.ny; ++J)
    for (int I = 0; I < coarse.nx; ++I) {
      // Same terms and order as the parallel form, written out per fine neighbour.
      const int i = 2 * I, j = 2 * J;
      Real sum = r_fine[fine.at(i, j)];
      sum += p.xw[coarse.at(I, J)] * r_fine[fine.at(i + 1, j)];
      sum += p.xe[coarse.at(I - 1, J)] * r_fine[fine.at(i - 1, j)];
      sum += p.ys[coarse.at(I, J)] * r_fine[fine.at(i, j + 1)];
      sum += p.yn[coarse.at(I, J - 1)] * r_fine[fine.at(i, j - 1)];
      sum += p.sw[coarse.at(I, J)] * r_fine[fine.at(i + 1, j + 1)];
      sum += p.se[coarse.at(I - 1, J)] * r_fine[fine.at(i - 1, j + 1)];
      sum += p.nw[coarse.at(I, J - 1)] * r_fine[fine.at(i + 1, j - 1)];
      sum += p.ne[coarse.at(I - 1, J - 1)] * r_fine[fine.at(i - 1, j - 1)];
      b_coarse[coarse.at(I, J)] = sum;
    }
}

// (P x) at each fine node by its parity, as prolong_correction_plain forms it (row loops with
// a vector fast path: multigrid_rows.h).
template <class Real>
void prolong_correction_rows(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p, const Real* x_coarse,
                             const std::uint8_t* fine_active, Real* x_fine, Execution execution) {
  const auto row_kernel = detail::stencil9_rows<Real>().prolong_correction;
  forall(
      fine.ny,
      [&](std::int64_t j) { row_kernel(fine, coarse, p, x_coarse, fine_active, x_fine, static_cast<int>(j)); },
      execution);
}

template <class Real>
void prolong_correction_plain(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p, const Real* x_coarse,
                              const std::uint8_t* fine_active, Real* x_fine) {
  for (int j = 0; j < fine.ny; ++j)
    for (int i = 0; i < fine.nx; ++i) {
      const std::int64_t t = fine.at(i, j);
      if (!fine_active[t]) continue;
      const int I = i / 2, J = j / 2;
      Real correction;
      if (i % 2 == 0 && j % 2 == 0) correction = x_coarse[coarse.at(I, J)];
      else if (j % 2 == 0) correction = p.xw[coarse.at(I, J)] * x_coarse[coarse.at(I, J)] + p.xe[coarse.at(I, J)] * x_coarse[coarse.at(I + 1, J)];
      else if (i % 2 == 0) correction = p.ys[coarse.at(I, J)] * x_coarse[coarse.at(I, J)] + p.yn[coarse.at(I, J)] * x_coarse[coarse.at(I, J + 1)];
      else
        correction = p.sw[coarse.at(I, J)] * x_coarse[coarse.at(I, J)] + p.se[coarse.at(I, J)] * x_coarse[coarse.at(I + 1, J)] +
                     p.nw[coarse.at(I, J)] * x_coarse[coarse.at(I, J + 1)] + p.ne[coarse.at(I, J)] * x_coarse[coarse.at(I + 1, J + 1)];
      x_fine[t] += correction;
    }
}

// Level 0 (double) with a double or float coarse level: sums in double, rounded once.
template <class Real>
void restrict_red_residual_rows(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p, const double* r_fine,
                                Real* b_coarse, Execution execution) {
  const std::int64_t cs = coarse.stride(), fs = fine.stride();
  forall(
      coarse.ny,
      [&](std::int64_t J64) {
        const int J = static_cast<int>(J64);
        const std::int64_t row = coarse.at(0, J);
        for (int I = 0; I < coarse.nx; ++I) {
          const std::int64_t c = row + I, f = fine.at(2 * I, 2 * J);
          b_coarse[c] = static_cast<Real>(r_fine[f] + p.sw[c] * r_fine[f + fs + 1] + p.se[c - 1] * r_fine[f + fs - 1] +
                                          p.nw[c - cs] * r_fine[f - fs + 1] + p.ne[c - cs - 1] * r_fine[f - fs - 1]);
        }
      },
      execution);
}

template <class Real>
void restrict_red_residual_plain(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p, const double* r_fine,
                                 Real* b_coarse) {
  for (int J = 0; J < coarse.ny; ++J)
    for (int I = 0; I < coarse.nx; ++I) {
      const int i = 2 * I, j = 2 * J;
      double sum = r_fine[fine.at(i, j)];
      sum += p.sw[coarse.at(I, J)] * r_fine[fine.at(i + 1, j + 1)];
      sum += p.se[coarse.at(I - 1, J)] * r_fine[fine.at(i - 1, j + 1)];
      sum += p.nw[coarse.at(I, J - 1)] * r_fine[fine.at(i + 1, j - 1)];
      sum += p.ne[coarse.at(I - 1, J - 1)] * r_fine[fine.at(i - 1, j - 1)];
      b_coarse[coarse.at(I, J)] = static_cast<Real>(sum);
    }
}

// Level 0 (double) from a double or float coarse level: the correction is formed in Real
// (row loops with a vector fast path: multigrid_rows.h).
template <class Real>
void prolong_correction_red_rows(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p, const Real* x_coarse,
                                 const std::uint8_t* fine_active, double* x_fine, Execution execution) {
  const auto row_kernel = detail::texel_transfer_rows<Real>().prolong_correction_red;
  forall(
      fine.ny,
      [&](std::int64_t j) { row_kernel(fine, coarse, p, x_coarse, fine_active, x_fine, static_cast<int>(j)); },
      execution);
}

template <class Real>
void prolong_correction_red_plain(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p, const Real* x_coarse,
                                  const std::uint8_t* fine_active, double* x_fine) {
  for (int j = 0; j < fine.ny; ++j)
    for (int i = 0; i < fine.nx; ++i) {
      const std::int64_t t = fine.at(i, j);
      if ((i + j) % 2 != 0 || !fine_active[t]) continue;
      const int I = i / 2, J = j / 2;
      if (i % 2 == 0)
        x_fine[t] += x_coarse[coarse.at(I, J)];
      else
        x_fine[t] += p.sw[coarse.at(I, J)] * x_coarse[coarse.at(I, J)] +
                     p.se[coarse.at(I, J)] * x_coarse[coarse.at(I + 1, J)] +
                     p.nw[coarse.at(I, J)] * x_coarse[coarse.at(I, J + 1)] +
                     p.ne[coarse.at(I, J)] * x_coarse[coarse.at(I + 1, J + 1)];
    }
}

}  // namespace

void restrict_residual(GridShape fine, GridShape coarse, InterpolationView p, const double* r_fine, double* b_coarse,
                       Execution execution) {
  restrict_residual_rows(fine, coarse, p, r_fine, b_coarse, execution);
}
void restrict_residual(GridShape fine, GridShape coarse, InterpolationViewFloat p, const float* r_fine,
                       float* b_coarse, Execution execution) {
  restrict_residual_rows(fine, coarse, p, r_fine, b_coarse, execution);
}
void restrict_residual_reference(GridShape fine, GridShape coarse, InterpolationView p, const double* r_fine,
                                 double* b_coarse) {
  restrict_residual_plain(fine, coarse, p, r_fine, b_coarse);
}
void restrict_residual_reference(GridShape fine, GridShape coarse, InterpolationViewFloat p, const float* r_fine,
                                 float* b_coarse) {
  restrict_residual_plain(fine, coarse, p, r_fine, b_coarse);
}
void prolong_correction(GridShape fine, GridShape coarse, InterpolationView p, const double* x_coarse,
                        const std::uint8_t* fine_active, double* x_fine, Execution execution) {
  prolong_correction_rows(fine, coarse, p, x_coarse, fine_active, x_fine, execution);
}
void prolong_correction(GridShape fine, GridShape coarse, InterpolationViewFloat p, const float* x_coarse,
                        const std::uint8_t* fine_active, float* x_fine, Execution execution) {
  prolong_correction_rows(fine, coarse, p, x_coarse, fine_active, x_fine, execution);
}
void prolong_correction_reference(GridShape fine, GridShape coarse, InterpolationView p, const double* x_coarse,
                                  const std::uint8_t* fine_active, double* x_fine) {
  prolong_correction_plain(fine, coarse, p, x_coarse, fine_active, x_fine);
}
void prolong_correction_reference(GridShape fine, GridShape coarse, InterpolationViewFloat p, const float* x_coarse,
                                  const std::uint8_t* fine_active, float* x_fine) {
  prolong_correction_plain(fine, coarse, p, x_coarse, fine_active, x_fine);
}
void restrict_red_residual(GridShape fine, GridShape coarse, InterpolationView p, const double* r_fine,
                           double* b_coarse, Execution execution) {
  restrict_red_residual_rows(fine, coarse, p, r_fine, b_coarse, execution);
}
void restrict_red_residual(GridShape fine, GridShape coarse, InterpolationViewFloat p, const double* r_fine,
                           float* b_coarse, Execution execution) {
  restrict_red_residual_rows(fine, coarse, p, r_fine, b_coarse, execution);
}
void restrict_red_residual_reference(GridShape fine, GridShape coarse, InterpolationView p, const double* r_fine,
                                     double* b_coarse) {
  restrict_red_residual_plain(fine, coarse, p, r_fine, b_coarse);
}
void restrict_red_residual_reference(GridShape fine, GridShape coarse, InterpolationViewFloat p, const double* r_fine,
                                     float* b_coarse) {
  restrict_red_residual_plain(fine, coarse, p, r_fine, b_coarse);
}
void prolong_correction_red(GridShape fine, GridShape coarse, InterpolationView p, const double* x_coarse,
                            const std::uint8_t* fine_active, double* x_fine, Execution execution) {
  prolong_correction_red_rows(fine, coarse, p, x_coarse, fine_active, x_fine, execution);
}
void prolong_correction_red(GridShape fine, GridShape coarse, InterpolationViewFloat p, const float* x_coarse,
                            const std::uint8_t* fine_active, double* x_fine, Execution execution) {
  prolong_correction_red_rows(fine, coarse, p, x_coarse, fine_active, x_fine, execution);
}
void prolong_correction_red_reference(GridShape fine, GridShape coarse, InterpolationView p, const double* x_coarse,
                                      const std::uint8_t* fine_active, double* x_fine) {
  prolong_correction_red_plain(fine, coarse, p, x_coarse, fine_active, x_fine);
}
void prolong_correction_red_reference(GridShape fine, GridShape coarse, InterpolationViewFloat p, const float* x_coarse,
                                      const std::uint8_t* fine_active, double* x_fine) {
  prolong_correction_red_plain(fine, coarse, p, x_coarse, fine_active, x_fine);
}

}  // namespace dgtex::kernels
