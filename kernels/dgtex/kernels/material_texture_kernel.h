#pragma once
// Material textures (thesis §5.6, Fig. 5.20): elements whose Young's modulus and
// thickness vary per texel over the element's parameter square. Values are taken at the
// nearest texel (piecewise constant), so a quadrature that gives every texel cell of
// constant material its own mapped element rule integrates them as exactly as the
// standard rule integrates a uniform element.
//
// Texture layout: W x H texels, rows top to bottom (row 0 at xi2 = +1), columns along xi1
// (column 0 at xi1 = -1): texel (i, j) covers xi1 in [-1 + 2i/W, -1 + 2(i+1)/W] and
// xi2 in [1 - 2(j+1)/H, 1 - 2j/H]. quad8 only.
//
// Shapes: connectivity #elements x npe; points (xi1, xi2, reference weight) per point,
// per-element lists concatenated (start: #elements + 1); sections one per point; blocks
// #elements x npe x npe x 9, forces #elements x npe x 3, mass #elements x npe x npe,
// weights #elements x npe, rotations and F one 3x3 (row-major) per point. One element (the
// stiffness: a fixed chunk of an element's points) per work item, so the parallel forms
// equal the serial ones (Execution::serial) bitwise.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// Units: consistent (SI: positions m, E Pa, h m, density kg/m^3; blocks N/m, forces N, mass kg).
#include <cstdint>
#include <vector>

#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/shape_functions.h"
#include "dgtex/kernels/shell_element_kernel.h"

namespace dgtex::kernels {

// Per-texel material of one element (absolute values, row-major as above).
struct MaterialTextureView {
  int width;
  int height;
  const double* youngs_modulus;  // #W*H
  const double* thickness;       // #W*H
};

// Cells no wider than this fraction of the element's side get the 2 x 2 Gauss rule instead
// of the element's 3 x 3. Why: on small cells the integrand is nearly polynomial of low
// degree, so 9 points a texel only cost time and memory (a texture whose texels all differ:
// 2.25x fewer points); on a curved element with a random 32 x 32 texture the stiffness moves
// by < 1e-6 of its largest entry (test_material_textures).
inline constexpr double kMaterialReducedRuleCell = 1.0 / 8;

// Quadrature of textured elements: a quadtree over the texels (top cell = the element);
// a cell whose texels all share E and h gets a Gauss rule mapped onto it (3 x 3, the element
// rule, so a uniform texture gives exactly the standard element rule; 2 x 2 on cells no
// wider than reduced_rule_cell of the element's side; 0: 3 x 3 everywhere), any other cell
// is split in halves along each side longer than one texel. Appends to
// start/points/sections; `base` gives each element's Poisson ratio and density (E and h
// come from the texture).
void material_texture_quadrature(ElementType type, std::int64_t count, const MaterialTextureView* textures,
                                 const ShellSection* base, std::vector<std::int64_t>& start,
                                 std::vector<double>& points, std::vector<ShellSection>& sections,
                                 double reduced_rule_cell = kMaterialReducedRuleCell);

// The points material_texture_quadrature gives one texture: per uniform quadtree cell 9, or
// 4 on cells no wider than reduced_rule_cell (one cell for a uniform texture).
std::int64_t material_texture_point_count(const MaterialTextureView& texture,
                                          double reduced_rule_cell = kMaterialReducedRuleCell);

struct PointSectionBatch {
  ElementType type;
  std::int64_t count;
  const int* connectivity;      // #elements x npe
  const double* positions;      // rest, #nodes x 3
  const std::int64_t* start;    // #elements + 1
  const double* points;         // (xi1, xi2, weight) per point
  const ShellSection* sections; // per point
};

// Membrane + bending stiffness with D evaluated per point (E h / (1 - nu^2) and
// E h^3 / (12 (1 - nu^2))); with rotations R K R^T per point and the corrective force of
// shell report eq. 48, as shell_element_stiffness. Summed as Gram products of the points'
// strain rows scaled by the Cholesky factor of D (accumulate_gram_upper: vectorised; a
// textured plate's assembly 1.1-1.5x faster than point by point, the rest of its time being
// the per-point geometry), in chunks of a fixed number of points.
// Needs E >= 0, h >= 0, -1 < nu < 1 and weights >= 0 at every point (else invalid_argument,
// naming the point).
void point_section_stiffness(const PointSectionBatch& batch, const double* rotations, double* blocks, double* forces,
                             Execution execution = Execution::parallel);
// point_section_stiffness with each point's rotation formed as it is needed, from the
// current positions (#nodes x 3): the rotations of point_section_deformation_gradients and
// polar_decomposition_batch, bitwise, without their two arrays (144 bytes a point: a
// 512 x 512 texture whose texels all differ would need 600 MB more for them).
void point_section_corotated_stiffness(const PointSectionBatch& batch, const double* current_positions,
                                       double* blocks, double* forces, Execution execution = Execution::parallel);
// The same stiffness and forces summed point by point, block by block (the reference of the
// Gram form; they agree to rounding).
void point_section_stiffness_reference(const PointSectionBatch& batch, const double* rotations, double* blocks,
                                       double* forces);
void point_section_deformation_gradients(const PointSectionBatch& batch, const double* current_positions, double* F,
                                         Execution execution = Execution::parallel);
// rho h(x) integral N^a N^b dA.
void point_section_mass(const PointSectionBatch& batch, double* mass, Execution execution = Execution::parallel);
// Integral of N^a dA and of rho h(x) N^a dA.
void point_section_load_weights(const PointSectionBatch& batch, double* area_weights, double* mass_weights,
                                Execution execution = Execution::parallel);

}  // namespace dgtex::kernels
