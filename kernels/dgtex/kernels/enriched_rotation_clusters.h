#pragma once
// Rotation clusters of texture-enriched elements: a coarser corotation than the per-point
// one of enriched_element_kernel.h, for elements whose enrichment stays fixed for many steps.
//
// Per point, K = sum_q R^_q K0_q R^_q^T (R^ = I_n (x) R, K0_q the rest stiffness of point q)
// is summed afresh every step from all of an element's texel-resolving quadrature points
// (accordion: 35k points, 450 DOFs, ~0.4 s). Here the points are grouped into clusters, and
// all points of a cluster turn with one rotation R_c:
//   K = sum_c R^_c K0_c R^_c^T,   K0_c = sum_{q in c} K0_q   (fixed: summed once),
//   f = sum_c R^_c K0_c (X0 - R^_c^T X0)                      (enriched X0 = 0),
// so a step costs one rotation of the 3 x 3 blocks of K0_c per cluster instead of the point
// sums. With one point per cluster this is the per-point corotation exactly.
//
// Clusters: the texels of one block of B x B texels that are connected without crossing a
// wall of any of the element's textures (so a cluster never straddles a cut: the two sides
// of a cut turn apart), holding the points whose texel (containing_texel) is among them.
// Blocks that hold a cut tip (a texel corner inside the tile where one wall edge ends) are
// quartered toward it down to a smaller size: the shell turns fastest around the tips (the
// hinges of an accordion).
// R_c is the polar rotation of the cluster's mean deformation gradient: the current
// tangents are linear in the DOFs, so their weighted means over the cluster are
// sum_f D_f x_f with D_f = sum_q w_q dN_f(q) (stored with K0_c); the rest ones likewise
// from the rest positions. The error against per-point
// rotations is of the order of the rotation's spread inside a cluster (B = 1: per texel).
//
// Shapes: rest data, cluster after cluster, enriched_cluster_rest_size doubles in all; per
// cluster of element e (n = enriched_basis_count(batch, e)), enriched_cluster_rest_stride
// (batch, e) doubles: 9 planes (entry i*3+j of a block) of the packed upper blocks (a, c),
// a <= c < n, at a*n - a*(a-1)/2 + (c-a), each plane enriched_cluster_packed_blocks(n) long
// (padded); then D_f (xi1 and xi2 parts) for f < n. Where the element is planar
// (enriched_element_planar_frame), a block is sum_ab g_ab E_a E_b^T + g_T T T^T in its
// frame (membrane rows in the plane, bending rows along T), so 5 planes hold g_11, g_12,
// g_21, g_22, g_T (x^T B y for the frame pairs) instead of 9: 5/9 of the memory and of the
// stream per step (accordion: 158 -> 88 MB), and K = sum_c sum_k g_k (R_c x) (R_c y)^T.
// Planar and curved elements may share a batch; each element's rest data is as wide as its
// own basis. Rotations: 3 x 3 row-major per cluster. Blocks and forces as
// enriched_element_stiffness's (#elements x W x W x 9, #elements x W x 3, W = batch.width;
// the slots beyond an element's n functions are 0).
// Kernel conventions (dgtex/kernels/forall.h); every entry is a sum in cluster order, so
// the parallel forms equal the serial ones bitwise for any thread count.
#include <cstdint>
#include <vector>

#include "dgtex/kernels/enriched_element_kernel.h"

namespace dgtex::kernels {

struct EnrichedRotationClusters {
  std::vector<std::int64_t> element_start;  // #elements + 1: the clusters of each element
  std::vector<std::int64_t> point_start;    // #clusters + 1: into points
  std::vector<std::int64_t> points;         // quadrature point indices by cluster, ascending

  std::int64_t count() const { return static_cast<std::int64_t>(point_start.size()) - 1; }
};

// The clusters of blocks of block_texels x block_texels texels (>= 1); a block holding a
// cut tip is quartered toward the tip down to tip_block_texels (>= 1; >= block_texels: no
// refinement). Clusters of an element are ordered by their first texel (row-major); points
// keep their order. Elements are labelled side by side (one serial union-find each); the
// result is the reference's for any thread count.
EnrichedRotationClusters enriched_rotation_clusters(const EnrichedElementBatch& batch,
                                                    const EnrichedQuadrature& quadrature, int block_texels,
                                                    int tip_block_texels, Execution execution = Execution::parallel);
// The serial reference twin: the rule written plainly (texel_in_domain per texel, a tile of
// the block walls labelled by label_components). For tests.
EnrichedRotationClusters enriched_rotation_clusters_reference(const EnrichedElementBatch& batch,
                                                              const EnrichedQuadrature& quadrature, int block_texels,
                                                              int tip_block_texels);

std::int64_t enriched_cluster_packed_blocks(int functions);
// Planes of element e's rest blocks: 5 where it is planar, else 9.
int enriched_cluster_rest_planes(const EnrichedElementBatch& batch, std::int64_t e);
std::int64_t enriched_cluster_rest_stride(const EnrichedElementBatch& batch, std::int64_t e);
std::int64_t enriched_cluster_rest_size(const EnrichedElementBatch& batch, const EnrichedRotationClusters& clusters);

// K0_c and D_f of every cluster (rest data, enriched_cluster_rest_size doubles); every entry
// is written (padding 0), so `rest` need not be zeroed.
void enriched_cluster_rest_stiffness(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                     const EnrichedRotationClusters& clusters, double* rest,
                                     Execution execution = Execution::parallel);
// The same for the elements with compute[e] != 0 only; the other elements' rest data is left
// as it is. Why: a basis change of a progressive cut leaves some elements' textures and
// functions bitwise as they were (the slinky: one of its four), and their rest data is
// then the one summed before (each cluster is summed on its own), which the caller copies in.
void enriched_cluster_rest_stiffness(const EnrichedElementBatch& batch, const EnrichedQuadrature& quadrature,
                                     const EnrichedRotationClusters& clusters, double* rest, const char* compute,
                                     Execution execution = Execution::parallel);
// One element's rest data after its node shifts changed and some of its functions were
// dropped, its textures (so its clusters and points) staying the same: the rest data of
// `clusters` clusters (each enriched_cluster_rest_stride long: `planes` planes of packed
// blocks, then D_f) of `old_functions` functions in `old_rest` gives that of `functions`
// in `rest`. Function f of the new basis is function from[f] of the old one (ascending;
// the standard functions first, from[f] = f); an enriched one is shifted along its node's
// standard function standard[f] by delta[f] = new shift - old shift, psi_new = psi_old -
// delta N_a (delta 0 for standard functions). The strain rows are linear in the function,
// so K_fg -> K_fg - delta_g K_f,a(g) - delta_f K_a(f),g + delta_f delta_g K_a(f),a(g) and
// D_f -> D_f - delta_f D_a(f): the sums over the points equal those summed afresh up to
// round-off, at O(n^2) a cluster instead of O(points n^2).
void enriched_cluster_rest_reshift(int planes, std::int64_t clusters, int old_functions, const double* old_rest,
                                   int functions, const int* from, const int* standard, const double* delta,
                                   double* rest, Execution execution = Execution::parallel);
// Where each element's rest data starts (#elements + 1 offsets into the rest data): an
// element's clusters are consecutive, so its rest data is one stretch.
std::vector<std::int64_t> enriched_cluster_rest_element_start(const EnrichedElementBatch& batch,
                                                              const EnrichedRotationClusters& clusters);

// R_c of every cluster from the current state (#(nodes + virtual nodes) x 3, as for
// enriched_element_corotated_stiffness).
void enriched_cluster_rotations(const EnrichedElementBatch& batch, const EnrichedRotationClusters& clusters,
                                const double* rest, const double* current, double* rotations,
                                Execution execution = Execution::parallel);

// K and the corrective forces (may be null) from the rest data and the clusters' rotations.
void enriched_element_clustered_stiffness(const EnrichedElementBatch& batch, const EnrichedRotationClusters& clusters,
                                          const double* rest, const double* rotations, double* blocks,
                                          double* forces, Execution execution = Execution::parallel);

// Serial reference of the three kernels above from scratch: D_f summed over each cluster's
// points, R_c as above, and K, f as the per-point reference kernel with every point of a
// cluster given R_c. Rotations (may be null) receives R_c.
void enriched_element_clustered_stiffness_reference(const EnrichedElementBatch& batch,
                                                    const EnrichedQuadrature& quadrature,
                                                    const EnrichedRotationClusters& clusters, const double* current,
                                                    double* blocks, double* forces, double* rotations = nullptr);

}  // namespace dgtex::kernels
