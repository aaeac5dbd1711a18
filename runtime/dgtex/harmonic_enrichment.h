#pragma once
// Harmonic enrichment textures (thesis §5.5): for one cut c_i on a tile carrying the walls
// of all cuts, H^i solves the 5-point texel Laplace problem (dgtex/laplace_direct.h) with
//  - Dirichlet data on the texels incident to c_i's lattice edges: +1 left of the cut's
//    direction, -1 right of it (§5.5.1), or caller-given values (e.g. +-sqrt(r));
//  - zero Neumann on the element boundary and on every wall (other cuts, §5.5.2; walls of
//    c_i itself sit between Dirichlet texels);
//  - value 0 on components that no Dirichlet datum reaches (§5.5.2);
//  - Dirichlet texels already flagged in the input tile kept (C0 data of neighbouring
//    elements for the one-ring solve of §5.5.3).
// A texel incident to c_i on several edges takes the mean of their side values (at a
// self-intersection of c_i a texel can lie left of one pass and right of another: 0).
// Components whose Dirichlet data are all one value v get exactly v without a solve (the
// harmonic solution there is that constant), so a complete cut gives exactly +-1.
//
// One-ring (§5.5.3): element tiles are placed into one block tile (assemble_tile_block),
// cuts are rasterised in block coordinates, harmonic_enrichment runs on the block, and
// extract_tile reads each element's tile back. A placed tile has one of 8 orientations,
// so neighbours whose parameter axes differ (unstructured quad meshes) fit together, and
// two tri6 tiles make a square (the second turned by 180°, orientation 2, same offset):
// their half-covered diagonal texels coincide and are shared, which couples the two
// triangles across the hypotenuse. Neighbour tiles placed as `dirichlet_neighbour`
// contribute only their texels coupled to region texels, as Dirichlet data with their
// stored values (C0 constraints); absent neighbours leave zero Neumann.
// Pure functions over caller-owned tiles (thread-safe on distinct tiles; a solve may use
// all OpenMP threads). H is dimensionless; positions in texel units.
#include <array>
#include <functional>
#include <vector>

#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/texel_grid.h"
#include "dgtex/laplace_problem.h"

namespace dgtex {

// Dirichlet value of a texel incident to the cut: texel index (j * width + i) and the side
// it lies on (+1 left of the cut's direction, -1 right).
using CutSideValue = std::function<double(int texel, int side)>;

// Marks the texels incident to the cut's edges as Dirichlet in `tile` (replacing their
// values and any earlier Dirichlet data there). Without `value`: +1 / -1.
void set_cut_dirichlet(kernels::TexelTile& tile, const kernels::CutRaster& cut);
void set_cut_dirichlet(kernels::TexelTile& tile, const kernels::CutRaster& cut, const CutSideValue& value);

struct HarmonicEnrichment {
  kernels::TexelTile tile;       // values: H; flags: the input's plus the cut's Dirichlet bits
  LaplaceSolveStats stats;       // of the CHOLMOD solve (zeros when no component needed one)
  int solved_components = 0;     // components that needed the linear solve
  int constant_components = 0;   // components set to their single Dirichlet value
};

// cut_tile: walls of all cuts of the element (cut included), inactive texels, optional
// extra Dirichlet texels (their values are data). Pass the walls-only tile for each cut,
// not another cut's result (whose Dirichlet bits would count as data). `cut` must have
// been rasterised into a tile of the same size. Crossing cuts: split the later one first
// (kernels::split_cut_at_crossings) and enrich each piece.
HarmonicEnrichment harmonic_enrichment(const kernels::TexelTile& cut_tile, const kernels::CutRaster& cut);
HarmonicEnrichment harmonic_enrichment(const kernels::TexelTile& cut_tile, const kernels::CutRaster& cut,
                                       const CutSideValue& value);

// --- One-ring blocks -------------------------------------------------------------------
// Orientation o in 0..7 maps a tile's texel (i, j) into the block: first mirror i
// (i -> T-1-i) if o >= 4, then turn (o & 3) quarter turns counter-clockwise
// ((i, j) -> (T-1-j, i) each), then add the offset.
struct PlacedTile {
  const kernels::TexelTile* tile = nullptr;  // T x T, T the same for all
  int offset_x = 0, offset_y = 0;            // block texel of the turned tile's texel (0, 0)
  int orientation = 0;
  bool dirichlet_neighbour = false;
};
// Block texel of a tile texel under a placement.
std::array<int, 2> block_texel(const PlacedTile& where, int i, int j);

// A width x height block: texels covered by an active texel of a region tile are active
// with that tile's value and Dirichlet bit (later tiles win on shared texels), walls are
// carried over (turned), texels of dirichlet_neighbour tiles become Dirichlet with their
// values where they are coupled to a region texel, everything else is inactive.
// std::invalid_argument if a tile falls outside the block or sizes differ.
kernels::TexelTile assemble_tile_block(const std::vector<PlacedTile>& tiles, int width, int height);
// The tile at `where` read back from a block: values, walls (turned back) and Dirichlet
// bits from the block, inactive texels from where.tile (its values and other flags are
// ignored). Walls of the block on the tile's own border have no place in a tile and are
// dropped (a cut exactly along an element edge is the mesh level's business).
kernels::TexelTile extract_tile(const kernels::TexelTile& block, const PlacedTile& where);

}  // namespace dgtex
