#pragma once
// texel_derivatives (enriched_basis.h) for whole texel rows at once: the same finite
// differences, bitwise, into planar arrays, for every texel of rows [row_begin, row_end) of
// one texture, from per-texel reachability bits instead of per-neighbour domain and wall
// look-ups (several times fewer operations per texel). texel_derivatives is its reference
// (tests/test_enrichment_quadrature_speed.cpp checks bitwise agreement on walls, inactive
// texels, tile borders and the tri6 diagonal).
// Rows are independent, so callers split a tile into row blocks across threads.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, nothing is kept.
#include "dgtex/kernels/enriched_basis.h"

namespace dgtex::kernels {

// Planar (structure-of-arrays) texel derivatives of a block of rows: the fields of
// TexelDerivatives, each an array with texel (i, j) at (j - row_begin) * T + i.
struct TexelDerivativePlanes {
  double* value;
  double* g[2];
  double* s[3];  // 11, 22, 12
};

// row_end is clipped to T; row_begin < 0 throws. Texels outside the domain
// (texel_in_domain false) get zeros (as a value-initialised TexelDerivatives).
void texel_derivative_rows(ElementType type, int resolution, const TextureView& texture, int row_begin, int row_end,
                           const TexelDerivativePlanes& out);

}  // namespace dgtex::kernels
