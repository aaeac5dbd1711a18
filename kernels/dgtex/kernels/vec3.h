#pragma once
// Small 3-vector and 3x3 helpers on raw double arrays, shared by the shell kernels.
// Inline pure functions on caller arrays (thread-safe); results in the inputs' units.
#include <cmath>

namespace dgtex::kernels {

inline double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline void cross3(const double* a, const double* b, double* c) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}
// Whether a and b lie along one line: a x b vanishes to 1e-9 of |a| |b| (so also when
// either is zero). The one test of a camera's up against its view (the renderer replaces
// such an up; scene files and `dgtex render` refuse one that was given).
inline bool parallel3(const double* a, const double* b) {
  double c[3];
  cross3(a, b, c);
  return !(std::sqrt(dot3(c, c)) > 1e-9 * std::sqrt(dot3(a, a)) * std::sqrt(dot3(b, b)));
}
inline void normalize3(double* v) {
  const double l = std::sqrt(dot3(v, v));
  v[0] /= l, v[1] /= l, v[2] /= l;
}

// B' = B R^T for a 3x3 row block (rows: Voigt strain components, columns: x, y, z): the
// strain rows of a corotated point.
inline void rotate_rows(const double B[9], const double R[9], double out[9]) {
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      out[r * 3 + c] = B[r * 3 + 0] * R[c * 3 + 0] + B[r * 3 + 1] * R[c * 3 + 1] + B[r * 3 + 2] * R[c * 3 + 2];
}
inline void rotate_rows(double B[9], const double R[9]) {
  double out[9];
  rotate_rows(B, R, out);
  for (int i = 0; i < 9; ++i) B[i] = out[i];
}

// Inverse of a row-major 3x3 matrix by cofactors (the caller ensures it is regular).
inline void invert3(const double m[9], double inv[9]) {
  const double c00 = m[4] * m[8] - m[5] * m[7], c01 = m[5] * m[6] - m[3] * m[8], c02 = m[3] * m[7] - m[4] * m[6];
  const double det = m[0] * c00 + m[1] * c01 + m[2] * c02;
  inv[0] = c00 / det;
  inv[3] = c01 / det;
  inv[6] = c02 / det;
  inv[1] = (m[2] * m[7] - m[1] * m[8]) / det;
  inv[4] = (m[0] * m[8] - m[2] * m[6]) / det;
  inv[7] = (m[1] * m[6] - m[0] * m[7]) / det;
  inv[2] = (m[1] * m[5] - m[2] * m[4]) / det;
  inv[5] = (m[2] * m[3] - m[0] * m[5]) / det;
  inv[8] = (m[0] * m[4] - m[1] * m[3]) / det;
}

// Deformation gradient F = [a1 a2 t][A1 A2 T0]^-1 (row-major) of a mid-surface point, from
// its rest tangents and normal (A1, A2, T0) and its current ones (a1, a2, t).
inline void surface_deformation_gradient(const double A1[3], const double A2[3], const double T0[3],
                                         const double a1[3], const double a2[3], const double t[3], double F[9]) {
  const double rest[9] = {A1[0], A2[0], T0[0], A1[1], A2[1], T0[1], A1[2], A2[2], T0[2]};
  const double cur[9] = {a1[0], a2[0], t[0], a1[1], a2[1], t[1], a1[2], a2[2], t[2]};
  double inv[9];
  invert3(rest, inv);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      F[i * 3 + j] = cur[i * 3 + 0] * inv[0 * 3 + j] + cur[i * 3 + 1] * inv[1 * 3 + j] + cur[i * 3 + 2] * inv[2 * 3 + j];
}

}  // namespace dgtex::kernels
