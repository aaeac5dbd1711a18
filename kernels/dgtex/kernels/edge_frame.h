#pragma once
// The frame of a mesh edge at one point, shared by the plain and the enriched edge kernels:
// unit tangent, in-plane normal and unit averaged normal as the columns of a row-major 3x3
// matrix, from the plus side's tangent dphi/dt and the sides' unit normals (minus_t0 null
// on a boundary edge). Corotation takes the edge's rotation from this frame.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// Dimensionless (unit vectors).
#include "dgtex/kernels/vec3.h"

namespace dgtex::kernels {

inline void edge_frame(const double tangent[3], const double plus_t0[3], const double* minus_t0, double frame[9]) {
  double f1[3] = {tangent[0], tangent[1], tangent[2]};
  normalize3(f1);
  double n[3] = {plus_t0[0], plus_t0[1], plus_t0[2]};
  if (minus_t0)
    for (int k = 0; k < 3; ++k) n[k] += minus_t0[k];
  const double nt = dot3(n, f1);
  for (int k = 0; k < 3; ++k) n[k] -= nt * f1[k];
  normalize3(n);
  double f2[3];
  cross3(n, f1, f2);
  for (int k = 0; k < 3; ++k) {
    frame[k * 3 + 0] = f1[k];
    frame[k * 3 + 1] = f2[k];
    frame[k * 3 + 2] = n[k];
  }
}

}  // namespace dgtex::kernels
