#pragma once
// The hand-over between the cut geometry (which cuts exist now, and their harmonic
// enrichment textures) and the shell mechanics (which assembles the enriched basis).
//
// One EnrichmentFunction is the generalised Heaviside H_i of one cut segment c_i
// (thesis §5.5), defined on the elements Omega_i it enriches:
//   - enriched_nodes: N_i, the nodes of every element that c_i touches (sorted, unique).
//     Each node a in N_i carries 3 extra DOFs q_i^a, the coefficients of the shifted
//     enrichment basis function (H_i(xi) - H_i(xi^a)) N^a(xi) (thesis eq. 5.26; the shift
//     keeps the Kronecker property, so Dirichlet conditions stay per node).
//   - elements: Omega_i, every element incident to a node of N_i (the supports of those
//     basis functions), each with a texture of H_i. Elements of Omega_i that c_i does not
//     touch still need H_i there (constant +-1 beyond a complete cut, harmonic near a tip).
// Texture layout (one T for the whole model): ElementTexture::tile is T x T with texel
// (i, j) at j*T + i; quad8 texel (i, j) covers xi in [-1+2i/T, -1+2(i+1)/T] x
// [-1+2j/T, -1+2(j+1)/T]; tri6 texel (i, j) covers [i/T, (i+1)/T] x [j/T, (j+1)/T] and
// texels with i + j > T - 1 are flagged inactive (kernels::is_tri6_texel_active).
// tile.values holds H_i at texel centres; tile.flags holds the walls of *all* cuts in the
// element (so finite differences never reach across any cut) and the inactive bits; the
// dirichlet bits carry no meaning here.
// Value types that own their node lists and texture tiles (copies, no references).
// H is dimensionless (+-1 across a complete cut).
#include <vector>

#include "dgtex/kernels/texel_grid.h"

namespace dgtex {

struct ElementTexture {
  int element = -1;
  kernels::TexelTile tile;
};

struct EnrichmentFunction {
  std::vector<int> enriched_nodes;       // N_i, sorted
  std::vector<ElementTexture> elements;  // Omega_i, sorted by element index
};

// Whether H is +-1 (or 0) at every texel: the Heaviside of pieces its cut, alone or with
// others, separates completely (a closed loop, a region two cuts close), which the Laplace
// solve sets exactly (one value of data on each component). A harmonic function (one with
// a crack tip) varies, so the scan usually ends at the first texels.
inline bool is_step_function(const EnrichmentFunction& function) {
  for (const ElementTexture& texture : function.elements)
    for (const double value : texture.tile.values)
      if (value != 0 && value != 1 && value != -1) return false;
  return true;
}

}  // namespace dgtex
