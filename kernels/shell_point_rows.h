#pragma once
// Private to the shell element and edge kernels: the strain rows of dgtex/kernels/
// shell_point.h (membrane_rows, normal_change_operator, bending_rows), rearranged for
// throughput. Same formulas; the per-point parts (1 / j0, the frame coefficients
// c_ia = phi0^a . e_i) are computed once per point instead of once per basis function,
// divisions become multiplications, and the normal-change operator T that the bending
// rows need is computed once and shared with the edge terms. Results agree with the
// shell_point.h forms to round-off (~1e-16 relative), not bitwise.
#include <algorithm>
#include <cmath>

#include "dgtex/kernels/shell_point.h"
#include "dgtex/kernels/vec3.h"

namespace dgtex::kernels::fast_rows {

struct PointFrame {
  double c[2][2];  // c[i][a] = phi0^a . e_i
  double inv_j0;
  const double* e1;
  const double* e2;
};

inline void make_point_frame(const RestPoint& p, const double e1[3], const double e2[3], PointFrame& f) {
  f.c[0][0] = dot3(p.dual1, e1);
  f.c[0][1] = dot3(p.dual2, e1);
  f.c[1][0] = dot3(p.dual1, e2);
  f.c[1][1] = dot3(p.dual2, e2);
  f.inv_j0 = 1.0 / p.j0;
  f.e1 = e1;
  f.e2 = e2;
}

// T = (I - t0 t0^T) [a1 dN2 - a2 dN1]x / j0 (row-major), as normal_change_operator.
inline void normal_change(const RestPoint& p, const PointFrame& f, const double dN[2], double T[9]) {
  const double w[3] = {p.a1[0] * dN[1] - p.a2[0] * dN[0], p.a1[1] * dN[1] - p.a2[1] * dN[0],
                       p.a1[2] * dN[1] - p.a2[2] * dN[0]};
  const double S[9] = {0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0};
  const double* t = p.t0;
  for (int j = 0; j < 3; ++j) {
    const double tS = t[0] * S[0 * 3 + j] + t[1] * S[1 * 3 + j] + t[2] * S[2 * 3 + j];
    for (int i = 0; i < 3; ++i) T[i * 3 + j] = (S[i * 3 + j] - t[i] * tS) * f.inv_j0;
  }
}

// Membrane rows [eps11, eps22, 2 eps12] x (x, y, z), as membrane_rows.
inline void membrane(const PointFrame& f, const double dN[2], double B[9]) {
  const double g0 = dN[0] * f.c[0][0] + dN[1] * f.c[0][1];
  const double g1 = dN[0] * f.c[1][0] + dN[1] * f.c[1][1];
  for (int k = 0; k < 3; ++k) {
    B[0 * 3 + k] = g0 * f.e1[k];
    B[1 * 3 + k] = g1 * f.e2[k];
    B[2 * 3 + k] = g1 * f.e1[k] + g0 * f.e2[k];
  }
}

// Bending rows [rho11, rho22, 2 rho12] x (x, y, z) from the normal change T, as bending_rows.
inline void bending(const RestPoint& p, const PointFrame& f, const double d2N[3], const double T[9], double B[9]) {
  const double* phi_ab[3] = {p.a11, p.a22, p.a12};
  double rho[3][3];
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k) {
      const double* q = phi_ab[r];
      rho[r][k] = -(d2N[r] * p.t0[k] + q[0] * T[0 * 3 + k] + q[1] * T[1 * 3 + k] + q[2] * T[2 * 3 + k]);
    }
  const double (&c)[2][2] = f.c;
  // Coefficients of rho_11, rho_22, rho_12 in the frame components (11, 22, 2 x 12).
  const double k00[3] = {c[0][0] * c[0][0], c[0][1] * c[0][1], 2 * c[0][0] * c[0][1]};
  const double k11[3] = {c[1][0] * c[1][0], c[1][1] * c[1][1], 2 * c[1][0] * c[1][1]};
  const double k01[3] = {2 * c[0][0] * c[1][0], 2 * c[0][1] * c[1][1], 2 * (c[0][0] * c[1][1] + c[0][1] * c[1][0])};
  for (int k = 0; k < 3; ++k) {
    B[0 * 3 + k] = k00[0] * rho[0][k] + k00[1] * rho[1][k] + k00[2] * rho[2][k];
    B[1 * 3 + k] = k11[0] * rho[0][k] + k11[1] * rho[1][k] + k11[2] * rho[2][k];
    B[2 * 3 + k] = k01[0] * rho[0][k] + k01[1] * rho[1][k] + k01[2] * rho[2][k];
  }
}

// The first-derivative part of evaluate_rest_point (tangents a1, a2 and unit normal t0),
// for the corotation kernels, which need nothing else: same arithmetic for these fields.
struct SurfaceFrame {
  double a1[3], a2[3], t0[3];
};

inline void evaluate_surface_frame(const ShapeValues& s, const int* nodes, const double* X, SurfaceFrame& f) {
  for (int d = 0; d < 3; ++d) f.a1[d] = f.a2[d] = 0;
  for (int a = 0; a < s.count; ++a) {
    const double* x = X + 3 * static_cast<long>(nodes[a]);
    for (int d = 0; d < 3; ++d) {
      f.a1[d] += s.dN[a][0] * x[d];
      f.a2[d] += s.dN[a][1] * x[d];
    }
  }
  double n[3];
  cross3(f.a1, f.a2, n);
  const double j = std::sqrt(dot3(n, n));
  for (int d = 0; d < 3; ++d) f.t0[d] = n[d] / j;
}

// K = L^T R over nk stacked rows for a symmetric K (n nodes, 3 n DOFs): only the upper
// block triangle is computed and mirrored, so K is exactly symmetric. Register tiles of
// 3 rows (one node's x, y, z) by 8 columns are summed over k in order; tiles start at the
// 8-column boundary at or left of the diagonal block (the few entries left of it are
// dropped). Columns 3 n up to the next multiple of 8 must be finite (zero padding).
// Block (a, b) goes to K + (a * block_stride + b) * 9. Inlined into callers compiled with
// target_clones: no sum is reassociated, so every instruction set rounds the same (with
// FMA contraction off).
constexpr int product_tile_columns = 8;
template <int Columns>
__attribute__((always_inline)) inline void symmetric_stacked_product(int n, int nk, const double (*L)[Columns],
                                                                     const double (*R)[Columns], int block_stride,
                                                                     double* K) {
  static_assert(Columns % product_tile_columns == 0, "rows are padded to whole tiles");
  const int ndof = 3 * n;
  for (int a = 0; a < n; ++a) {
    const int row = 3 * a;
    for (int c0 = row / product_tile_columns * product_tile_columns; c0 < ndof; c0 += product_tile_columns) {
      alignas(64) double acc[3][product_tile_columns] = {};
      for (int k = 0; k < nk; ++k) {
        const double s0 = L[k][row], s1 = L[k][row + 1], s2 = L[k][row + 2];
        const double* d = R[k] + c0;
        for (int c = 0; c < product_tile_columns; ++c) {
          acc[0][c] += s0 * d[c];
          acc[1][c] += s1 * d[c];
          acc[2][c] += s2 * d[c];
        }
      }
      for (int c = std::max(c0, row); c < std::min(c0 + product_tile_columns, ndof); ++c) {
        const int b = c / 3, j = c % 3;
        for (int i = 0; i < 3; ++i) {
          K[(a * block_stride + b) * 9 + i * 3 + j] = acc[i][c - c0];
          if (b != a) K[(b * block_stride + a) * 9 + j * 3 + i] = acc[i][c - c0];
        }
      }
    }
  }
}

// Membrane and bending rows Bm, Bb of every basis function at a rest point (shape values s
// over the element's nodes), in the point's frame along a1; returns the area element j0.
// Depends on the rest geometry only.
inline double rest_strain_rows(const ShapeValues& s, const int* nodes, const double* X, int npe, double (*Bm)[9],
                               double (*Bb)[9]) {
  RestPoint p;
  evaluate_rest_point(s, nodes, X, p);
  double e1[3], e2[3];
  frame_along(p, p.a1, e1, e2);
  PointFrame frame;
  make_point_frame(p, e1, e2, frame);
  for (int a = 0; a < npe; ++a) {
    double T[9];
    membrane(frame, s.dN[a], Bm[a]);
    normal_change(p, frame, s.dN[a], T);
    bending(p, frame, s.d2N[a], T, Bb[a]);
  }
  return p.j0;
}

}  // namespace dgtex::kernels::fast_rows
