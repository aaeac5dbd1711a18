#pragma once
// Small 3-vector helpers on raw double[3] arrays, shared by the shell kernels.
#include <cmath>

namespace dgtex::kernels {

inline double dot3(const double* a, const double* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline void cross3(const double* a, const double* b, double* c) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}
inline void normalize3(double* v) {
  const double l = std::sqrt(dot3(v, v));
  v[0] /= l, v[1] /= l, v[2] /= l;
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

}  // namespace dgtex::kernels
