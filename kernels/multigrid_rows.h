#pragma once
// Internal to the multigrid kernels: the row loops of the smoothers, residuals and CG updates,
// each with a vector fast path (multigrid_rows.cpp), for the texel level (level 0) and the
// 9-point coarse levels.
//
// Level 0: most texels are unknowns coupled to four unknown neighbours; for them the 5-point row is
// x(t) times 4 minus the four neighbours, no flag decoding needed. A row is walked in groups
// of four texels from i = 0: a group of four such texels is done with GCC vector extensions
// (4 doubles), any other group texel by texel with the flag byte, exactly as the references
// do. Both paths run the same IEEE operations in the same order (no contraction into FMA:
// multigrid_rows.cpp is compiled with -ffp-contract=off, its AVX2 path enables no FMA), so
// the results are bitwise those of the plain loops on every machine.
//
// On processors with AVX-512 the level-0 loops that read flag bytes (colour sweep, colour
// residual, first sweep from zero, operator) take 8 texels a vector, and groups with walls,
// cuts or Dirichlet neighbours stay vectors: each neighbour term is masked to 0 by its
// coupling bit and the degree byte picks 1 / degree, the references' operations per lane.
//
// Coarse levels (9-point, double or float): groups of four nodes are computed as vectors
// whatever their operator (a node without unknown has c = 0 and is left alone), in the
// references' order of terms; a colour sweep stores only its own lanes.
//
// Row sums (norms, dot products) have one fixed order for the kernels and their references
// alike (RowSum): texel i goes to lane i mod 4, in increasing i, and the total is
// (lane 0 + lane 1) + (lane 2 + lane 3). Four chains instead of one let the vector path add
// four texels at once; the order depends on the row only, never on the thread count.
//
// Measured (callgrind, open T = 256, 1 thread): the smoothing sweep took ~37 instructions per
// texel with the stride-2 flag-decoding loop; see laplace_multigrid.cpp for the timings.
#include <cstdint>
#include <cstring>

#include "dgtex/kernels/multigrid_grid.h"
#include "dgtex/kernels/multigrid_unknowns.h"

namespace dgtex::kernels::detail {

typedef double Lanes4 __attribute__((vector_size(32)));

// Row sum in the fixed four-lane order described above.
struct RowSum {
  double lane[4] = {0.0, 0.0, 0.0, 0.0};
  void add(int i, double v) { lane[i & 3] += v; }
  double total() const { return (lane[0] + lane[1]) + (lane[2] + lane[3]); }
};

// The row loops; `j` is the row, arrays are in the padded level layout (multigrid_grid.h).
struct TexelRowKernels {
  // Gauss-Seidel update of the unknowns with (i + j) % 2 == color.
  void (*smooth_color)(GridShape, const std::uint8_t* bits, const double* b, double* x, int j, int color);
  // smooth_color(j, color), then smooth_color(j - 1, 1 - color) (j >= 1), the same bits: a
  // sweep's first colour on row j with its lagged second colour (lagged_rows).
  void (*smooth_color_pair)(GridShape, const std::uint8_t* bits, const double* b, double* x, int j, int color);
  // First forward sweep from x = 0: red unknowns b / degree, every other node 0.
  void (*red_from_zero)(GridShape, const std::uint8_t* bits, const double* b, double* x, int j);
  // red_from_zero(j), then smooth_color(j - 1, 1) (j >= 1), the same bits (as smooth_color_pair).
  void (*red_from_zero_pair)(GridShape, const std::uint8_t* bits, const double* b, double* x, int j);
  // r = b - A x at the unknowns with (i + j) % 2 == color (0 at other nodes of that colour).
  void (*residual_color)(GridShape, const std::uint8_t* bits, const double* b, const double* x, double* r, int j,
                         int color);
  // r = b - A x (0 off the unknowns); returns the RowSum of r^2.
  double (*residual)(GridShape, const std::uint8_t* bits, const double* b, const double* x, double* r, int j);
  // y = A x (0 off the unknowns); returns the RowSum of y x.
  double (*apply)(GridShape, const std::uint8_t* bits, const double* x, double* y, int j);
  // Returns the RowSum of a b.
  double (*dot)(GridShape, const double* a, const double* b, int j);
  // x += alpha p, r -= alpha q; returns the RowSum of r^2.
  double (*cg_update)(GridShape, double alpha, const double* p, const double* q, double* x, double* r, int j);
  // p = z + beta p.
  void (*direction)(GridShape, const double* z, double beta, double* p, int j);
};

// The fastest form this processor runs (chosen once per process).
const TexelRowKernels& texel_rows();
// A given form, for the tests that check the forms agree bitwise; avx2 needs avx2_supported(),
// avx512 avx512_supported() (the 9-point and transfer loops have no AVX-512 form: avx512
// gives their AVX2 form).
enum class RowPath { baseline, avx2, avx512 };
bool avx2_supported();
bool avx512_supported();
const TexelRowKernels& texel_rows(RowPath path);

// 9-point levels, Real = double or float.
template <class Real>
struct Stencil9RowKernels {
  // Gauss-Seidel update of the nodes with i % 2 == ci and c > 0 (one colour of row j). It
  // rewrites row j's other nodes with their own values: no other thread may access row j
  // during the call.
  void (*smooth_color)(GridShape, Stencil9ViewOf<Real> a, const Real* b, Real* x, int j, int ci);
  // r = b - A x (0 where c = 0).
  void (*residual)(GridShape, Stencil9ViewOf<Real> a, const Real* b, const Real* x, Real* r, int j);
  // Fine row j (a 9-point level): x += P x_c at the nodes whose fine_active byte is 1
  // (prolong_correction; the coarse level is fine.coarser()).
  void (*prolong_correction)(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p, const Real* x_coarse,
                             const std::uint8_t* fine_active, Real* x_fine, int j);
};
template <class Real>
const Stencil9RowKernels<Real>& stencil9_rows();
template <class Real>
const Stencil9RowKernels<Real>& stencil9_rows(RowPath path);

// Level 0 to level 1 (Real = level 1's type).
template <class Real>
struct TexelTransferRowKernels {
  // Coarse row J of P^T r, r = b - A x at the red unknowns ((i + j) even) and 0 elsewhere
  // (restrict_red_residual_texels).
  void (*red_residual_restricted)(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p,
                                  const std::uint8_t* bits, const double* b, const double* x, Real* b_coarse, int J);
  // Fine row j: x += P x_c at the red nodes whose fine_active byte is 1 (prolong_correction_red).
  void (*prolong_correction_red)(GridShape fine, GridShape coarse, InterpolationViewOf<Real> p, const Real* x_coarse,
                                 const std::uint8_t* fine_active, double* x_fine, int j);
};
template <class Real>
const TexelTransferRowKernels<Real>& texel_transfer_rows();
template <class Real>
const TexelTransferRowKernels<Real>& texel_transfer_rows(RowPath path);

// Scalar per-texel forms shared by the fast paths and the references.
// 1 / degree by the degree bits (computed as 1.0 / d, as the references divide).
constexpr double inverse_degree[8] = {0.0, 1.0, 1.0 / 2.0, 1.0 / 3.0, 1.0 / 4.0, 0.0, 0.0, 0.0};
inline double texel_smoothed(std::uint8_t m, const double* b, const double* x, std::int64_t t, std::int64_t s) {
  const double sum = b[t] + ((m & couples_west_unknown) ? x[t - 1] : 0.0) +
                     ((m & couples_east_unknown) ? x[t + 1] : 0.0) + ((m & couples_south_unknown) ? x[t - s] : 0.0) +
                     ((m & couples_north_unknown) ? x[t + s] : 0.0);
  return sum * inverse_degree[laplace_degree(m)];
}
inline double texel_operator(std::uint8_t m, const double* x, std::int64_t t, std::int64_t s) {
  return laplace_degree(m) * x[t] - ((m & couples_west_unknown) ? x[t - 1] : 0.0) -
         ((m & couples_east_unknown) ? x[t + 1] : 0.0) - ((m & couples_south_unknown) ? x[t - s] : 0.0) -
         ((m & couples_north_unknown) ? x[t + s] : 0.0);
}
// b - A x at texel t, 0 off the unknowns.
inline double texel_residual(std::uint8_t m, const double* b, const double* x, std::int64_t t, std::int64_t s) {
  return (m & is_unknown) ? b[t] - texel_operator(m, x, t, s) : 0.0;
}

}  // namespace dgtex::kernels::detail
