#pragma once
// Element terms of texture-enriched DG shells: membrane + bending stiffness (shell report
// eqs. 32-33), consistent mass and load weights, for the local basis of enriched_basis.h
// (npe standard functions, then the enriched ones), integrated with the quadrature of
// enriched_quadrature.h. Corotated per quadrature point like shell_element_kernel.h: the
// deformation gradient includes the enriched DOFs, whose rest value is zero, so their
// share of the corrective term R K (I - R^T) X0 vanishes.
//
// Shapes (W = batch.width, points as in enriched_quadrature.h):
//   blocks #elements x W x W x 9 (block (a, b) at (a*W+b)*9), forces #elements x W x 3,
//   mass #elements x W x W (times I3), weights #elements x W, rotations and F: one 3x3
//   (row-major) per quadrature point in the order of the point list. Padding slots are 0.
// current (deformation gradients): #(nodes + virtual nodes) x 3, indexed by the global
// nodes of enriched_global_nodes: current positions of nodes, then the current values of
// the enriched DOFs. The parallel forms equal the serial ones bitwise (fixed work items).
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// Units: consistent (SI: positions m, E Pa, h m, density kg/m^3; blocks N/m, forces N, mass kg).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "dgtex/kernels/enriched_basis.h"
#include "dgtex/kernels/forall.h"

namespace dgtex::kernels {

struct EnrichedQuadrature {
  const std::int64_t* start;  // #elements + 1
  const double* points;       // (xi1, xi2, reference weight) per point
};

// Stiffness blocks and corrective forces. Fast form: a texture whose gradient and Hessian
// (parametric units, over the point's texel) are both at most enriched_flat_tolerance is
// locally constant there, so its enriched functions are the multiples (H_k - H_k(xi^a)) N^a
// of standard ones; such points only need the rows of the standard functions and of the
// textures that vary there. Points with the same varying textures and the same constant
// values (within the tolerance) form a group whose small matrix sum_q S_q^T S_q is mapped
// onto the element's basis once (K += T^T G T). A point's six strain rows are five numbers
// per function times its rotated frame (membrane rows in the tangent plane, bending rows
// along t0), so each 3 x 3 component block (k, l) of G is U^T W_kl U + t_k t_l B^T B over
// the functions' two membrane and three bending factors (U, B; W_kl from the frame, t the
// rotated normal; the six bending sums share each point's B^T B, weighted by t_k t_l):
// 13.5 m^2 multiply-adds a point for m functions instead of 27 m^2 for the rows of 3 m
// columns. The factors of up to 16 points of a group are stacked and summed by blocked
// products (register tiles, a path per instruction set, no FMA contraction: every path
// rounds alike). Complete cuts' +-1 are exact; harmonic
// tails below the tolerance move K by about that much relative (1e-10, far below the
// quadrature's merge tolerance). Work items are fixed chunks (each element's points split
// into at most enriched_chunks_per_element equal ranges of at least enriched_chunk_points),
// summed per element in chunk order: bitwise independent of the thread count.
void enriched_element_stiffness(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                const double* rotations, double* blocks, double* forces,
                                Execution execution = Execution::parallel);
// The corotated stiffness from the current state (#(nodes + virtual nodes) x 3, as for
// enriched_element_deformation_gradients) in one pass: each point's F and rotation
// (polar_rotation) are formed where its rows are, sharing the texture samples. Bitwise
// equal to enriched_element_deformation_gradients, polar_decomposition_batch and
// enriched_element_stiffness with those rotations.
void enriched_element_corotated_stiffness(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                          const double* current, double* blocks, double* forces,
                                          Execution execution = Execution::parallel);
// Planar elements. Where an element's rest nodes lie in one plane (each within
// enriched_planar_tolerance times the element's size of it), every point has the same
// tangent plane and normal, so the unrotated strain rows need no 3 columns per function.
// The unrotated forms (enriched_element_stiffness without rotations,
// enriched_element_point_set_stiffness) then sum one membrane row a point, the function
// gradients along two fixed in-plane directions E1, E2 (2n columns: their products, from
// which the plane-stress stiffness is formed per block afterwards), and three bending rows
// along the normal T (n columns): 3.5 n^2 instead of 27 n^2 multiply-adds per point, the
// same K to round-off. A 3 x 3 block (a, c) is then sum_k g_k x_k y_k^T over the five frame
// pairs (x, y) = (E1, E1), (E1, E2), (E2, E1), (E2, E2), (T, T) (enriched_planar_pairs).
// enriched_element_planar_frame tells whether element e is planar and gives its frame
// (rows E1, E2, T; E1 along the rest tangent a1 and T the rest normal t0 at the element's
// centre; row-major 3 x 3), the same for every call. enriched_planar_frame_products gives
// the five products (R x)(R y)^T (R null: x y^T), 3 x 3 row-major each.
constexpr double enriched_planar_tolerance = 1e-12;
constexpr int enriched_planar_pairs[5][2] = {{0, 0}, {0, 1}, {1, 0}, {1, 1}, {2, 2}};
bool enriched_element_planar_frame(const EnrichedElementBatch& batch, std::int64_t e, double frame[9]);
void enriched_planar_frame_products(const double frame[9], const double* R, double products[45]);
// Where block (a, c), a <= c, of a planar element's sums K = [Km | Kb] over n functions
// (enriched_element_point_set_stiffness) keeps its five frame sums, in
// enriched_planar_pairs order: Km(2a + x, 2c + y) for the four in-plane pairs, Kb(a, c).
void enriched_planar_sum_offsets(int n, std::size_t a, std::size_t c, std::size_t at[5]);

// Plain per-point form (every basis function at every point; serial): the reference.
void enriched_element_stiffness_reference(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                          const double* rotations, double* blocks, double* forces);
// The rest (unrotated) stiffness of element e summed over the listed quadrature points
// only, by the fast form's arithmetic: K is 3n x 3n row-major over the element's DOFs
// (n = enriched_basis_count), of which block rows a <= c are written (each 3 x 3 block
// (a, c), a <= c, whole); the rest is left as it was. For a planar element
// (enriched_element_planar_frame) K holds instead the membrane sums Km, 2n x 2n row-major
// over (function, E1 | E2), then the bending sums Kb, n x n over functions along T, each
// with block rows a <= c (2 x 2 and 1 x 1 blocks): block (a, c) of the stiffness is
// sum_xy Km(2a + x, 2c + y) E_x E_y^T + Kb(a, c) T T^T. tangent_weights (optional, 2 n
// doubles) receives D_f = sum_q w_q dN_f(q) (xi1 and xi2 parts) from the same pass,
// bitwise as summed from evaluate_enriched_shape in point order. Serial.
void enriched_element_point_set_stiffness(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                          std::int64_t e, const std::int64_t* points, std::int64_t count,
                                          std::vector<double>& K, double* tangent_weights = nullptr);
constexpr double enriched_flat_tolerance = 1e-10;
constexpr std::int64_t enriched_chunk_points = 2048;
// Each chunk maps its groups onto a 3n x 3n sum of its own and keeps their G matrices
// (up to ~2 MB each for accordion's 150 functions): fewer, longer chunks map less and
// reduce less. Accordion (1 element, 35k points, 2 threads, loaded machine): 2048-point
// chunks (18) ~250 ms per assembly, 16 chunks ~230, 8 ~230, 4 ~188. Caps the threads
// one element can use in the point phase at 4 (the block-row reduction uses them all).
constexpr std::int64_t enriched_chunks_per_element = 4;

void enriched_element_deformation_gradients(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                            const double* current, double* F,
                                            Execution execution = Execution::parallel);

void enriched_element_mass(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature, double* mass,
                           Execution execution = Execution::parallel);

void enriched_element_load_weights(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                   double* area_weights, double* mass_weights,
                                   Execution execution = Execution::parallel);

}  // namespace dgtex::kernels
