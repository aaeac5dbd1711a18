#pragma once
// The enriched basis of texture-enriched DG shells (thesis §5.3-5.5, eq. 5.25-5.26):
//   u(xi) = sum_a N^a(xi) u^a + sum_k sum_{a in N_k} (H_k(xi) - H_k(xi^a)) N^a(xi) q_k^a,
// with H_k an enrichment texture (values at texel centres, walls on texel edges).
//
// Interpolation of H between texel centres (the "texel rule"): inside texel t, H is the
// local quadratic Taylor polynomial about the texel centre c_t,
//   H(x) = H_t + g_t . d + 1/2 d^T S_t d,   d = x - c_t (texel units),
// whose gradient g_t and Hessian S_t are finite differences of the texel values that never
// reach across a wall, an inactive texel or the tile border. Per direction:
//   both neighbours reachable:     g = (H+ - H-)/2,            S = H+ - 2H + H-   (central, O(h^2))
//   one side only (+), 2 reachable: g = (-3H + 4H+ - H++)/2,   S = H - 2H+ + H++  (one-sided, O(h^2) / O(h))
//   one side only, 1 reachable:     g = H+ - H,                S = 0
//   isolated:                       g = 0,                     S = 0
// The mixed term S_12 is the mean of d/dxi2 of g_1 and d/dxi1 of g_2, each by the same
// central / one-sided first difference of the neighbours' own g (again never across a
// wall). The value, first and second derivatives at a point are the exact derivatives of
// that texel's polynomial, so they are mutually consistent inside a texel; quadratic
// fields are reproduced exactly everywhere (walls aside); smooth fields give first
// derivatives to O(h^2) and second derivatives to O(h) (O(h^2) at texel centres away from
// walls). A point on a texel edge belongs to the texel with the larger index, clamped into
// the tile, and for tri6 moved down in j into the active triangle (see containing_texel);
// the node shifts H_k(xi^a) are sampled by this same rule.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// H is dimensionless; derivatives are per unit of the element parameters xi.
#include <cstdint>

#include "dgtex/kernels/shape_functions.h"
#include "dgtex/kernels/shell_element_kernel.h"

namespace dgtex::kernels {

// One enrichment texture of one element: T x T texels (texel (i, j) at j * T + i) with H at
// texel centres and the texel_grid.h flags (walls of all cuts of the element, inactive).
struct TextureView {
  const double* values = nullptr;
  const std::uint8_t* flags = nullptr;
};

// Value and parametric derivatives (d2 columns: 11, 22, 12 as in ShapeValues).
struct TextureSample {
  double value = 0;
  double d[2] = {0, 0};
  double d2[3] = {0, 0, 0};
};

// Texel-centred finite differences in texel units (see the rule above).
struct TexelDerivatives {
  double value = 0;
  double g[2] = {0, 0};
  double s[3] = {0, 0, 0};  // 11, 22, 12
};

// Parametric size of a texel (quad8: 2/T, tri6: 1/T) and the centre of texel (i, j).
double texel_size(ElementType type, int resolution);
void texel_centre(ElementType type, int resolution, int i, int j, double xi[2]);
// Whether texel (i, j) is inside the tile, not flagged inactive, and (tri6) in the triangle.
bool texel_in_domain(ElementType type, int resolution, const std::uint8_t* flags, int i, int j);
// The texel whose polynomial evaluates H at xi (rule in the header comment).
void containing_texel(ElementType type, int resolution, double xi1, double xi2, int& i, int& j);

void texel_derivatives(ElementType type, int resolution, const TextureView& texture, int i, int j,
                       TexelDerivatives& out);
// H at xi from the polynomial of texel (i, j) (any xi: extrapolates outside the texel).
void sample_texture_in_texel(ElementType type, int resolution, const TextureView& texture, int i, int j, double xi1,
                             double xi2, TextureSample& out);
void sample_texture(ElementType type, int resolution, const TextureView& texture, double xi1, double xi2,
                    TextureSample& out);
// The same polynomial from already computed texel derivatives (sample_texture_in_texel is
// texel_derivatives followed by this; kernels cache the derivatives per texel).
void sample_texel_polynomial(ElementType type, int resolution, const TexelDerivatives& fd, int i, int j, double xi1,
                             double xi2, TextureSample& out);

// ---------------------------------------------------------------------------------------
// Elements carrying enriched basis functions. An "element enrichment" is one texture H_k on
// one element; enrichment_start (count + 1) groups them per element in the order of k.
// Local basis of an enriched element: its npe standard functions, then for every element
// enrichment j in order and every local node a (ascending) with enriched_node[j*npe+a] >= 0
// the function (H_j - node_shift[j*npe+a]) N^a. width >= that count for every element: the
// padded local size of all outputs; unused local slots have global node -1.
constexpr int max_enrichments_per_element = 31;
constexpr int max_enriched_basis = max_element_nodes * (1 + max_enrichments_per_element);

struct TexelDerivativeTile;

struct EnrichedElementBatch {
  ElementType type;
  std::int64_t count;              // enriched elements
  const int* element;              // mesh element of each (#count)
  const int* connectivity;         // #mesh elements x npe
  const double* positions;         // rest positions, #nodes x 3
  const ShellSection* sections;    // per mesh element
  int resolution;                  // T
  int width;                       // padded local basis size
  const int* enrichment_start;     // #count + 1
  const TextureView* textures;     // per element enrichment
  const int* enriched_node;        // per element enrichment x npe: global (virtual) node or -1
  const double* node_shift;        // per element enrichment x npe: H_j(xi^a)
  // Optional, per element enrichment like textures: the texel derivatives of that texture
  // (texel_derivative_tile.h) or null. Kernels that sample texel polynomials read a tile
  // instead of recomputing texel_derivatives (the same bits in the domain; outside it they
  // compute). The adaptive quadrature builds the tiles; ShellModel passes them on.
  const TexelDerivativeTile* const* derivatives = nullptr;
};

// Number of local basis functions of enriched element e (npe + enriched ones).
int enriched_basis_count(const EnrichedElementBatch& batch, std::int64_t e);
// Global node of each local basis function (width entries, -1 padded).
void enriched_global_nodes(const EnrichedElementBatch& batch, std::int64_t e, int* global_nodes);

// All local basis functions at xi (the standard ones first, as evaluate_shape gives them).
struct EnrichedShapeValues {
  int count = 0;
  double N[max_enriched_basis];
  double dN[max_enriched_basis][2];
  double d2N[max_enriched_basis][3];
};
void evaluate_enriched_shape(const EnrichedElementBatch& batch, std::int64_t e, double xi1, double xi2,
                             const ShapeValues& standard, EnrichedShapeValues& out);

}  // namespace dgtex::kernels
