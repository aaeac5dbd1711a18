#pragma once
// Enrichment functions of complete cuts on one element tile (thesis §5.4.1-5.4.2, App. A.2).
// The input "cut tile" carries the walls of all cuts of the element (and the inactive
// texels of a tri6); components are the flood-fill components of kernels/flood_fill.h.
//  - canonical Heavisides H_c^k: 1 on component C_k, 0 elsewhere (§5.4.2), k in the
//    canonical component order (by smallest texel index);
//  - the generalized Heaviside of one complete cut: +1 on the components left of the
//    cut's direction, -1 on those right of it, 0 on components it does not touch (§5.4.1,
//    and the "Neumann-only components are 0" rule of §5.5.2). This is the harmonic
//    enrichment of a complete cut on one tile, obtained without a solve, as the thesis
//    defines it; the cut manager's region solves give an untouched component the value
//    beyond its walls instead (mesh_texel_laplace.h).
// Values are written into tile.values of tiles that copy the input's flags.
// Pure functions over caller-owned tiles (thread-safe on distinct tiles). Values are
// dimensionless (+-1, 0).
#include <vector>

#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/texel_grid.h"

namespace dgtex {

// One tile per component of cut_tile: values 1 on the component, 0 elsewhere (inactive 0).
std::vector<kernels::TexelTile> canonical_heavisides(const kernels::TexelTile& cut_tile);

// Whether `cut` (rasterised into cut_tile) is complete there: some texel lies on each
// side of it, and no component touches both of its sides.
bool is_complete_cut(const kernels::TexelTile& cut_tile, const kernels::CutRaster& cut);

// The +-1 / 0 generalized Heaviside of a complete cut. Throws std::invalid_argument
// (naming a texel that can be reached from both sides) if the cut is partial there;
// use harmonic_enrichment for partial cuts.
kernels::TexelTile complete_cut_heaviside(const kernels::TexelTile& cut_tile, const kernels::CutRaster& cut);

}  // namespace dgtex
