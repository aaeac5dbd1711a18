#include "shell_point_rows_batch.h"

#include <algorithm>
#include <cmath>

#include "dgtex/kernels/vec3.h"

namespace dgtex::kernels::fast_rows {
namespace {

constexpr int L = kRestRowLanes;
using Lanes = double[L];

// The vec3.h operations, lane by lane, in the same order.
inline void dot(const Lanes* a, const Lanes* b, Lanes& out) {
  for (int l = 0; l < L; ++l) out[l] = a[0][l] * b[0][l] + a[1][l] * b[1][l] + a[2][l] * b[2][l];
}

inline void cross(const Lanes* a, const Lanes* b, Lanes* c) {
  for (int l = 0; l < L; ++l) {
    c[0][l] = a[1][l] * b[2][l] - a[2][l] * b[1][l];
    c[1][l] = a[2][l] * b[0][l] - a[0][l] * b[2][l];
    c[2][l] = a[0][l] * b[1][l] - a[1][l] * b[0][l];
  }
}

// dN[a][k][l] = shapes[l].dN[a][k]; lanes from count on repeat the last point.
inline void first_derivatives(const ShapeValues* shapes, int count, int npe, double (*dN)[2][L]) {
  for (int l = 0; l < L; ++l) {
    const ShapeValues& s = shapes[std::min(l, count - 1)];
    for (int a = 0; a < npe; ++a)
      for (int k = 0; k < 2; ++k) dN[a][k][l] = s.dN[a][k];
  }
}

// sums[k] = sum over the nodes a (in order) of coefficient[a][k] times node a's position:
// the tangents (coefficients dN) or the second derivatives (d2N) of the surface.
template <int K>
inline void node_sums(const double (*coefficient)[K][L], const int* nodes, const double* X, int npe,
                      Lanes* const (&sums)[K]) {
  for (int k = 0; k < K; ++k)
    for (int d = 0; d < 3; ++d)
      for (int l = 0; l < L; ++l) sums[k][d][l] = 0;
  for (int a = 0; a < npe; ++a) {
    const double* x = X + 3 * static_cast<long>(nodes[a]);
    for (int k = 0; k < K; ++k)
      for (int d = 0; d < 3; ++d)
        for (int l = 0; l < L; ++l) sums[k][d][l] += coefficient[a][k][l] * x[d];
  }
}

// rest_tangents: a1, a2 and the normal n = a1 x a2, and j0 = |n|.
inline void tangents_and_area(const double (*dN)[2][L], const int* nodes, const double* X, int npe, Lanes* a1,
                              Lanes* a2, Lanes* n, Lanes& j0) {
  node_sums<2>(dN, nodes, X, npe, {a1, a2});
  cross(a1, a2, n);
  dot(n, n, j0);
  for (int l = 0; l < L; ++l) j0[l] = std::sqrt(j0[l]);
}

}  // namespace

__attribute__((target_clones("avx512f", "avx2", "default"))) void rotate_rows_batch(const double (*R)[9],
                                                                                     int count, int npe,
                                                                                     RestRowsBatch& rows) {
  alignas(64) double r_lanes[9][L];
  for (int l = 0; l < L; ++l)
    for (int i = 0; i < 9; ++i) r_lanes[i][l] = R[std::min(l, count - 1)][i];
  for (int a = 0; a < npe; ++a)
    for (double(*B)[L] : {rows.Bm[a], rows.Bb[a]}) {
      alignas(64) double out[9][L];
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          for (int l = 0; l < L; ++l)
            out[r * 3 + c][l] = B[r * 3 + 0][l] * r_lanes[c * 3 + 0][l] + B[r * 3 + 1][l] * r_lanes[c * 3 + 1][l] +
                                B[r * 3 + 2][l] * r_lanes[c * 3 + 2][l];
      std::copy(&out[0][0], &out[0][0] + 9 * L, &B[0][0]);
    }
}

__attribute__((target_clones("avx512f", "avx2", "default"))) void deformation_gradient_batch(
    const ShapeValues* shapes, int count, const int* nodes, const double* X, const double* current, int npe,
    double (*F)[9]) {
  alignas(64) double dN[max_element_nodes][2][L];
  first_derivatives(shapes, count, npe, dN);
  // evaluate_surface_frame at rest (A1, A2, T0) and now (a1, a2, t).
  alignas(64) double A1[3][L], A2[3][L], N0[3][L], J0[L], a1[3][L], a2[3][L], n[3][L], j[L];
  tangents_and_area(dN, nodes, X, npe, A1, A2, N0, J0);
  tangents_and_area(dN, nodes, current, npe, a1, a2, n, j);
  for (int d = 0; d < 3; ++d)
    for (int l = 0; l < L; ++l) N0[d][l] /= J0[l], n[d][l] /= j[l];
  for (int l = 0; l < count; ++l) {
    const double rest_a1[3] = {A1[0][l], A1[1][l], A1[2][l]}, rest_a2[3] = {A2[0][l], A2[1][l], A2[2][l]};
    const double rest_t[3] = {N0[0][l], N0[1][l], N0[2][l]};
    const double now_a1[3] = {a1[0][l], a1[1][l], a1[2][l]}, now_a2[3] = {a2[0][l], a2[1][l], a2[2][l]};
    const double now_t[3] = {n[0][l], n[1][l], n[2][l]};
    surface_deformation_gradient(rest_a1, rest_a2, rest_t, now_a1, now_a2, now_t, F[l]);
  }
}

__attribute__((target_clones("avx512f", "avx2", "default"))) void rest_area_factor_batch(
    const ShapeValues* shapes, int count, const int* nodes, const double* X, int npe, double* j0) {
  alignas(64) double dN[max_element_nodes][2][L];
  first_derivatives(shapes, count, npe, dN);
  alignas(64) double a1[3][L], a2[3][L], n[3][L], area[L];
  tangents_and_area(dN, nodes, X, npe, a1, a2, n, area);
  std::copy(area, area + count, j0);
}

__attribute__((target_clones("avx512f", "avx2", "default"))) void rest_strain_rows_batch(
    const ShapeValues* shapes, int count, const int* nodes, const double* X, int npe, RestRowsBatch& out) {
  alignas(64) double dN[max_element_nodes][2][L], d2N[max_element_nodes][3][L];
  first_derivatives(shapes, count, npe, dN);
  for (int l = 0; l < L; ++l) {
    const ShapeValues& s = shapes[std::min(l, count - 1)];
    for (int a = 0; a < npe; ++a)
      for (int k = 0; k < 3; ++k) d2N[a][k][l] = s.d2N[a][k];
  }
  // evaluate_rest_point: tangents, normal, area element, second derivatives, dual basis.
  alignas(64) double a1[3][L], a2[3][L], n[3][L], j0[L];
  tangents_and_area(dN, nodes, X, npe, a1, a2, n, j0);
  alignas(64) double a11[3][L], a22[3][L], a12[3][L];
  node_sums<3>(d2N, nodes, X, npe, {a11, a22, a12});
  alignas(64) double t0[3][L], dual1[3][L], dual2[3][L];
  for (int d = 0; d < 3; ++d)
    for (int l = 0; l < L; ++l) t0[d][l] = n[d][l] / j0[l];
  cross(a2, t0, dual1);
  cross(t0, a1, dual2);
  for (int d = 0; d < 3; ++d)
    for (int l = 0; l < L; ++l) dual1[d][l] /= j0[l], dual2[d][l] /= j0[l];
  // frame_along(a1) and make_point_frame.
  alignas(64) double tn[L], t[3][L], length[L], e1[3][L], e2[3][L];
  dot(a1, t0, tn);
  for (int d = 0; d < 3; ++d)
    for (int l = 0; l < L; ++l) t[d][l] = a1[d][l] - tn[l] * t0[d][l];
  dot(t, t, length);
  for (int l = 0; l < L; ++l) length[l] = std::sqrt(length[l]);
  for (int d = 0; d < 3; ++d)
    for (int l = 0; l < L; ++l) e1[d][l] = t[d][l] / length[l];
  cross(t0, e1, e2);
  alignas(64) double c00[L], c01[L], c10[L], c11[L], inv_j0[L];
  dot(dual1, e1, c00);
  dot(dual2, e1, c01);
  dot(dual1, e2, c10);
  dot(dual2, e2, c11);
  for (int l = 0; l < L; ++l) inv_j0[l] = 1.0 / j0[l];
  // Bending coefficients of rho_11, rho_22, rho_12 (as fast_rows::bending).
  alignas(64) double k00[3][L], k11[3][L], k01[3][L];
  for (int l = 0; l < L; ++l) {
    k00[0][l] = c00[l] * c00[l], k00[1][l] = c01[l] * c01[l], k00[2][l] = 2 * c00[l] * c01[l];
    k11[0][l] = c10[l] * c10[l], k11[1][l] = c11[l] * c11[l], k11[2][l] = 2 * c10[l] * c11[l];
    k01[0][l] = 2 * c00[l] * c10[l], k01[1][l] = 2 * c01[l] * c11[l];
    k01[2][l] = 2 * (c00[l] * c11[l] + c01[l] * c10[l]);
  }
  const Lanes* phi_ab[3] = {a11, a22, a12};
  for (int a = 0; a < npe; ++a) {
    double(*Bm)[L] = out.Bm[a];
    double(*Bb)[L] = out.Bb[a];
    for (int l = 0; l < L; ++l) {
      // membrane
      const double g0 = dN[a][0][l] * c00[l] + dN[a][1][l] * c01[l];
      const double g1 = dN[a][0][l] * c10[l] + dN[a][1][l] * c11[l];
      for (int k = 0; k < 3; ++k) {
        Bm[0 * 3 + k][l] = g0 * e1[k][l];
        Bm[1 * 3 + k][l] = g1 * e2[k][l];
        Bm[2 * 3 + k][l] = g1 * e1[k][l] + g0 * e2[k][l];
      }
      // normal_change
      const double w[3] = {a1[0][l] * dN[a][1][l] - a2[0][l] * dN[a][0][l],
                           a1[1][l] * dN[a][1][l] - a2[1][l] * dN[a][0][l],
                           a1[2][l] * dN[a][1][l] - a2[2][l] * dN[a][0][l]};
      const double S[9] = {0, -w[2], w[1], w[2], 0, -w[0], -w[1], w[0], 0};
      double T[9];
      for (int j = 0; j < 3; ++j) {
        const double tS = t0[0][l] * S[0 * 3 + j] + t0[1][l] * S[1 * 3 + j] + t0[2][l] * S[2 * 3 + j];
        for (int i = 0; i < 3; ++i) T[i * 3 + j] = (S[i * 3 + j] - t0[i][l] * tS) * inv_j0[l];
      }
      // bending
      double rho[3][3];
      for (int r = 0; r < 3; ++r)
        for (int k = 0; k < 3; ++k) {
          const Lanes* q = phi_ab[r];
          rho[r][k] =
              -(d2N[a][r][l] * t0[k][l] + q[0][l] * T[0 * 3 + k] + q[1][l] * T[1 * 3 + k] + q[2][l] * T[2 * 3 + k]);
        }
      for (int k = 0; k < 3; ++k) {
        Bb[0 * 3 + k][l] = k00[0][l] * rho[0][k] + k00[1][l] * rho[1][k] + k00[2][l] * rho[2][k];
        Bb[1 * 3 + k][l] = k11[0][l] * rho[0][k] + k11[1][l] * rho[1][k] + k11[2][l] * rho[2][k];
        Bb[2 * 3 + k][l] = k01[0][l] * rho[0][k] + k01[1][l] * rho[1][k] + k01[2][l] * rho[2][k];
      }
    }
  }
  std::copy(j0, j0 + L, out.j0);
}

}  // namespace dgtex::kernels::fast_rows
