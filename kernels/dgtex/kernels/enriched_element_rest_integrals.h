#pragma once
// Consistent mass and load weights of texture-enriched elements in one pass over their
// quadrature points: bitwise equal to enriched_element_mass and
// enriched_element_load_weights (enriched_element_kernel.h), which evaluate every point
// twice and use one thread per element. Here each point's basis values (N only, no
// derivatives; texel derivatives reused while consecutive points stay in one texel) are
// evaluated once, in parallel over fixed blocks of points, and then summed per element in
// point order, the elements side by side: the same sums as the two kernels, for any thread
// count, and a single large element (one-element scenes at T = 256) uses all threads.
// Shapes as in enriched_element_kernel.h: mass #elements x W x W (times I3), weights
// #elements x W, padding slots 0. Kernel conventions (dgtex/kernels/forall.h): arrays are
// the caller's, nothing is kept after a call; thread-safe on distinct outputs.
// Units: consistent (SI: kg for mass and mass weights, m^2 for area weights).
#include "dgtex/kernels/enriched_element_kernel.h"
#include "dgtex/kernels/texel_derivative_tile.h"

namespace dgtex::kernels {

// Points evaluated per work item (one texel cache each).
constexpr std::int64_t rest_integral_block_points = 256;

void enriched_element_mass_and_load_weights(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                            double* mass, double* area_weights, double* mass_weights,
                                            Execution execution = Execution::parallel);
// The same (bitwise), reading texel derivatives from derivatives[m] for the batch's texture
// m (enrichment_start order) where that is not null (texel_derivative_tile.h).
// basis_values (optional): the local basis values the sums use, kept for the caller. Point q
// (numbered as in quadrature.start) gets W slots at basis_values + q * W, and its element's
// first enriched_basis_count entries are written. A basis change's projection reads them
// instead of evaluating the new basis at every point again.
void enriched_element_mass_and_load_weights(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                            const TexelDerivativeTile* const* derivatives, double* mass,
                                            double* area_weights, double* mass_weights,
                                            Execution execution = Execution::parallel, double* basis_values = nullptr);

// evaluate_enriched_shape's N (bitwise) at xi of enriched element e, standard shape s;
// `cache` holds the texel derivatives of e's textures at texel (cache_i, cache_j) and is
// refilled when the point's texel differs (start with cache_i = -1). Returns the count.
struct EnrichedTexelCache {
  std::int64_t element = -1;
  int i = -1, j = -1;
  TexelDerivatives fields[max_enrichments_per_element];
};
// derivatives (optional): per texture of the batch (like batch.textures), a tile to read
// the texel derivatives from, or null; texels outside the domain are computed regardless.
int enriched_shape_values(const EnrichedElementBatch& batch, std::int64_t e, double xi1, double xi2,
                          const ShapeValues& s, EnrichedTexelCache& cache, double* N,
                          const TexelDerivativeTile* const* derivatives = nullptr);

}  // namespace dgtex::kernels
