#pragma once
// Eikonal distance on a texel tile by first-order upwind fast marching (Sethian 1996):
// thesis §5.6 "Creases": the enrichment of a crease is the geodesic distance from the
// crease line, computed by a fast marching method.
//
// Units: texel (i, j) has its centre at ((i + 0.5) spacing_x, (j + 0.5) spacing_y) in the
// caller's length unit; spacing_x / spacing_y are the lengths of one texel step along i / j
// (an element's metric, taken constant over the tile: an orthogonal, affine approximation).
// Neighbours are the 4-connected texels; a wall (texel_grid.h) or an inactive texel blocks
// propagation, so distances go around cuts. The update solves
//   ((d - a) / spacing_x)^2 + ((d - b) / spacing_y)^2 = 1
// with a, b the smallest known neighbour along each axis (one-axis update where only one
// side is known or the quadratic has no root >= max(a, b)). First-order accurate: the
// error against the exact distance is O(texel) (exact along the axes).
//
// Only a serial reference form exists: fast marching is inherently sequential (texels
// are accepted one by one in order of distance from a heap); its cost is
// O(n log n) for n texels, small against the Laplace solves of cuts.
// Deterministic: heap ties are broken by texel index.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
#include <cstdint>
#include <vector>

#include "dgtex/kernels/cut_rasterization.h"
#include "dgtex/kernels/texel_grid.h"

namespace dgtex::kernels {

// tile.values at texels with seeded[k] != 0 are the given (fixed) distances; every other
// active texel gets the marched distance. Texels not reachable from a seed (walled off,
// or no seed at all) are set to +infinity; the return value is their count. Inactive
// texels are left unchanged. Throws std::invalid_argument for a seeded vector of the wrong
// size, spacings that are not finite and positive, or a negative / non-finite seed value.
int fast_marching_reference(TexelTile& tile, const std::vector<std::uint8_t>& seeded, double spacing_x,
                            double spacing_y);

// Seeds the texels whose centre lies within `band` (caller's length unit) of a polyline
// given in continuous texel coordinates (cut_rasterization.h): tile.values gets the exact
// distance (with the spacings applied) and seeded[k] = 1; other texels are untouched
// (seeded is resized to the tile and keeps earlier seeds, taking the smaller distance).
// Inactive texels are skipped. Returns the number of texels seeded by this call. Throws
// std::invalid_argument for fewer than 2 points, non-finite points, or bad spacings/band.
int seed_polyline_distance(const std::vector<TexelPoint>& polyline, TexelTile& tile, std::vector<std::uint8_t>& seeded,
                           double spacing_x, double spacing_y, double band);

}  // namespace dgtex::kernels
