#pragma once
// Private to the material-texture kernels (material_texture_kernel.cpp): the per-point
// geometry of up to kRestRowLanes points of one element at once: the rest strain rows of
// fast_rows::rest_strain_rows (shell_point_rows.h), their rotation for corotated points, the
// surface deformation gradients and the area elements. Every quantity is held across the
// points (one lane each), so the arithmetic vectorises across points (target_clones:
// AVX-512, AVX2, baseline); each lane takes the operations of the one-point form in the
// same order, so with FMA contraction off the results are bitwise those. Why: the per-point
// geometry was ~60 % of a textured element's assembly (session 42's profile), scalar and
// latency-bound.
#include "dgtex/kernels/shape_functions.h"

namespace dgtex::kernels::fast_rows {

constexpr int kRestRowLanes = 8;

struct RestRowsBatch {
  // Bm[a][r][l]: membrane row r (eps11, eps22, 2 eps12 times x, y, z) of node a at lane l's
  // point; Bb likewise for bending; j0[l]: the area element there.
  alignas(64) double Bm[max_element_nodes][9][kRestRowLanes];
  alignas(64) double Bb[max_element_nodes][9][kRestRowLanes];
  alignas(64) double j0[kRestRowLanes];

  // Lane l's rows in the one-point layout of rest_strain_rows.
  void lane(int l, int npe, double (*Bm_out)[9], double (*Bb_out)[9]) const {
    for (int a = 0; a < npe; ++a)
      for (int r = 0; r < 9; ++r) Bm_out[a][r] = Bm[a][r][l], Bb_out[a][r] = Bb[a][r][l];
  }
};

// shapes[0 .. count): the points' shape values over the element's npe nodes (1 <= count <=
// kRestRowLanes); lanes from count on repeat the last point.
void rest_strain_rows_batch(const ShapeValues* shapes, int count, const int* nodes, const double* X, int npe,
                            RestRowsBatch& out);

// Rotates every lane's rows in place, B <- B R_l^T (rotate_rows, dgtex/kernels/vec3.h),
// R[l] lane l's rotation (row-major, l < count), bitwise as rotate_rows: the strain rows
// of corotated points.
void rotate_rows_batch(const double (*R)[9], int count, int npe, RestRowsBatch& rows);

// The surface deformation gradients F[0 .. count) (row-major) between the rest positions X
// and the current ones at the same points, bitwise the one-point form
// (evaluate_surface_frame at rest and now, surface_deformation_gradient).
void deformation_gradient_batch(const ShapeValues* shapes, int count, const int* nodes, const double* X,
                                const double* current, int npe, double (*F)[9]);

// The area elements j0 = |a1 x a2| alone (rest_area_factor, shell_point.h) at the same
// points, bitwise those of the one-point form: j0[0 .. count).
void rest_area_factor_batch(const ShapeValues* shapes, int count, const int* nodes, const double* X, int npe,
                            double* j0);

}  // namespace dgtex::kernels::fast_rows
