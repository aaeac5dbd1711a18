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

}  // namespace dgtex::kernels
