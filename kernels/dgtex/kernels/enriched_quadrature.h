#pragma once
// Quadrature of enriched elements that resolves the enrichment textures only where they
// vary ("integrate densely only where the field demands it").
//
// Rule (a quadtree over the element's T x T texels, top cell = the whole tile):
//  - A cell is a rectangle of texels; for tri6 it is either inside the triangle, or a square
//    on the diagonal (i0 + j0 + L == T) of which only the lower-left triangle counts, or
//    split further (cells outside the triangle are dropped).
//  - A cell of more than one texel is *merged* when (adaptive only) no wall separates two
//    of its texels and, for every enrichment H_k of the element, the texel polynomials of
//    enriched_basis.h agree with the one of a reference texel c of the cell:
//      |H_t - P_c(x_t)|,  L |g_t - grad P_c(x_t)|,  L^2 |S_t - S_c|   <= merge_tolerance
//    for every texel t of the cell (L: cell size in texels). Constant H (complete cuts away
//    from the cut) and quadratic H pass with tolerance 0. A merged cell gets the element's
//    standard rule mapped onto it (quad8: 3x3 Gauss; tri6: Radon's 7 points on triangles,
//    3x3 Gauss on rectangles inside the triangle); a merged top cell is exactly the standard
//    element rule.
//    Exception: along a side of at most 2 texels a merged rectangle takes 2 Gauss points,
//    not 3 (fewer points; each then lies near a texel centre instead of on the texel edge
//    where the texel polynomials meet, which cut the compliance error of the rule against
//    the per-texel one ~25x at the default tolerance: dgtex bench accuracy --charts quadrature).
//  - Otherwise the cell is split (adaptive; rectangular cells, i.e. not the tri6 diagonal or
//    cells crossing it): AT a wall line if one runs along >= 3/4 of an interior texel line
//    of the cell (the such line closest to the cell's middle, ties: horizontal, then lower),
//    so a straight cut ends up on cell borders and each side merges as soon as the textures
//    are smooth there, instead of refining to single texels along the whole wall; else in
//    two halves of its long side only when the cell is elongated (w >= 2h or h >= 2w),
//    else in halves in both directions. Other cells: in halves in both directions. A single texel
//    gets the per-texel rule: 2x2 Gauss on a square texel, Radon's 7 points on a tri6
//    diagonal half-texel. Staircase (curved) walls have no long line and keep the halving.
//  - adaptive = false: every texel gets the per-texel rule (the dense reference).
// Points are (xi1, xi2, weight) with weights including the reference area, as in
// element_quadrature. Per-element point lists are concatenated in element order
// (start: #elements + 1 offsets), so serial and parallel forms give identical arrays.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// Points are element parameters (dimensionless); merge_tolerance is in units of H (O(1)).
#include <cstdint>
#include <memory>
#include <vector>

#include "dgtex/kernels/enriched_basis.h"
#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/texel_derivative_tile.h"

namespace dgtex::kernels {

struct EnrichedQuadratureOptions {
  bool adaptive = true;
  // In units of H (H is O(1): +-1 across a cut). 1e-2: on a T = 256 spiral cut it takes
  // 9k points instead of 71k at 1e-4 (assembly 7x faster) and moves the displacements by
  // 1e-5 relative.
  double merge_tolerance = 1e-2;
};

// Parallel inside an element too (row blocks of the per-texel set-up, quadtree subtrees);
// the arrays are bitwise those of the reference for any thread count.
void enriched_element_quadrature(const EnrichedElementBatch& batch, const EnrichedQuadratureOptions& options,
                                 std::vector<std::int64_t>& start, std::vector<double>& points,
                                 Execution execution = Execution::parallel);
// The same, also handing out the texel derivatives it computed: (*derivatives)[m] for the
// batch's texture m (enrichment_start order), null where it computed none (adaptive false).
void enriched_element_quadrature(const EnrichedElementBatch& batch, const EnrichedQuadratureOptions& options,
                                 std::vector<std::int64_t>& start, std::vector<double>& points,
                                 std::vector<std::shared_ptr<const TexelDerivativeTile>>* derivatives,
                                 Execution execution = Execution::parallel);
// The serial reference twin: the rule written plainly (each candidate cell re-tests all its
// texels for domain, walls and polynomial agreement). For tests.
void enriched_element_quadrature_reference(const EnrichedElementBatch& batch, const EnrichedQuadratureOptions& options,
                                           std::vector<std::int64_t>& start, std::vector<double>& points);

// Deviation test of the rule above over an explicit list of texels (texel units; used by
// the element cells and by the edge segments): true if every texture's polynomials at
// `texels` (pairs i, j) agree with the one at `reference` within tolerance.
bool texels_share_one_quadratic(ElementType type, int resolution, const TextureView* textures, int texture_count,
                                const int* texels, int texel_count, const int reference[2], double size,
                                double tolerance);

}  // namespace dgtex::kernels
