#pragma once
// The texel derivatives (texel_derivatives, enriched_basis.h) of every texel of one
// texture, as the adaptive enriched quadrature builds them (texel_derivative_rows in row
// blocks), kept so that the enriched mass, load weights and the projection moments of a
// basis change read them instead of recomputing them per quadrature point: texel_derivatives
// was ~16% of the instructions of a chad basis change (T = 256), all of it done before.
// Bitwise equal to texel_derivatives for texels in the domain (texel_in_domain); outside it
// the tile holds zeros where texel_derivatives does not, so callers test the domain first.
// Immutable once built; shared (std::shared_ptr) between the models that use it.
// Units: those of the texture values per texel.
#include <cstddef>
#include <memory>
#include <vector>

#include "dgtex/kernels/enriched_basis.h"
#include "dgtex/kernels/texel_derivative_rows.h"

namespace dgtex::kernels {

struct TexelDerivativeTile {
  int resolution = 0;      // T
  int rows_per_block = 0;  // rows of each block
  // Per row block: six planes (value, g1, g2, s11, s22, s12) of rows_per_block x T each.
  std::vector<std::unique_ptr<double[]>> blocks;

  TexelDerivativeTile(int t, int rows) : resolution(t), rows_per_block(rows), blocks((t + rows - 1) / rows) {}
  // Row j's planes (texel (i, j) at index i of each); the block must be allocated.
  TexelDerivativePlanes row(int j) const {
    double* block = blocks[static_cast<std::size_t>(j / rows_per_block)].get();
    const std::size_t plane = static_cast<std::size_t>(rows_per_block) * resolution;
    const std::size_t offset = static_cast<std::size_t>(j % rows_per_block) * resolution;
    return {block + offset, {block + plane + offset, block + 2 * plane + offset},
            {block + 3 * plane + offset, block + 4 * plane + offset, block + 5 * plane + offset}};
  }
  void at(int i, int j, TexelDerivatives& out) const {
    const TexelDerivativePlanes r = row(j);
    out.value = r.value[i];
    out.g[0] = r.g[0][i];
    out.g[1] = r.g[1][i];
    for (int k = 0; k < 3; ++k) out.s[k] = r.s[k][i];
  }
};

}  // namespace dgtex::kernels
