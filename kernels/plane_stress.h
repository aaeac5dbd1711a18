#pragma once
// Private to the shell element kernels (shell_element_kernel.cpp, its reference
// shell_stiffness_reference.cpp, and the textured material_texture_kernel.cpp): the
// plane-stress law on Voigt vectors, and the last product of the corotational corrective
// force (shell report eq. 48), which all three form alike.
#include "dgtex/kernels/shape_functions.h"

namespace dgtex::kernels {

// C = [[1, nu, 0], [nu, 1, 0], [0, 0, (1-nu)/2]] times scale, applied to a Voigt vector.
inline void apply_plane_stress(double nu, double scale, const double in[3], double out[3]) {
  out[0] = scale * (in[0] + nu * in[1]);
  out[1] = scale * (nu * in[0] + in[1]);
  out[2] = scale * 0.5 * (1 - nu) * in[2];
}

// f += w (Bm^T sm + Bb^T sb) over the element's npe nodes: Bm, Bb the point's rotated
// membrane and bending rows, sm, sb the stresses D B (X0 - R^T X0) of its unrotated ones.
inline void add_corrective_force(int npe, const double (*Bm)[9], const double (*Bb)[9], const double sm[3],
                                 const double sb[3], double w, double* f) {
  for (int a = 0; a < npe; ++a)
    for (int i = 0; i < 3; ++i) {
      double v = 0;
      for (int r = 0; r < 3; ++r) v += Bm[a][r * 3 + i] * sm[r] + Bb[a][r * 3 + i] * sb[r];
      f[a * 3 + i] += w * v;
    }
}

}  // namespace dgtex::kernels
