#pragma once
// Edge terms of texture-enriched DG shells: the penalty, consistency and symmetry terms of
// shell_edge_kernel.h on the hinge component g = dt(u) . nu, for edges where either side
// (or both) carries enriched basis functions: interior edges inside Omega_i, edges on the
// outer boundary of Omega_i (N^a vanishes there but its normal derivative does not, so
// the enriched functions still enter the hinge term), and clamped boundary edges.
//
// Local basis of an edge (enriched_edge_local_layout): its plus side's local basis, then its
// minus side's (each its element's, enriched_basis.h order; a non-enriched side has just its
// npe standard functions), m = widths[e] functions in all. Outputs: blocks, each edge's
// m x m block matrix from block_start[e] (no padding to the widest edge: fracture's edge
// blocks padded took 46 MB, 81 % of it unused), forces m x 3 from function_start[e], per-point
// rotations (one 3x3 per edge quadrature point). Every entry is written (blocks as 0 on an
// edge without quadrature points). enriched_edge_global_nodes's padded slots (side s at
// [s W, s W + W), W = elements->width) serve the rotations' reads of current positions.
//
// Edge quadrature (t in [-1, 1], in the plus element's direction): the edge is split into
// T pieces of equal t-length (each piece lies on one border texel per side, the diagonal
// texels for a tri6 hypotenuse) and a binary tree over the pieces merges a segment when
// on both sides every enrichment's border texels of the segment share one quadratic
// (texels_share_one_quadratic, same tolerance as the elements). A merged segment gets
// `quadrature_points` Gauss points (a merged whole edge: exactly the standard edge rule);
// a single unmerged piece gets 2 Gauss points. Points: (t, weight) pairs, weights summing
// to 2 over an edge; concatenated per edge in order (start: #edges + 1).
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// Units: consistent (SI: positions m, E Pa, h m, density kg/m^3; blocks N/m, forces N, mass kg).
#include <cstdint>
#include <vector>

#include "dgtex/kernels/enriched_basis.h"
#include "dgtex/kernels/enriched_quadrature.h"
#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/shell_element_kernel.h"

namespace dgtex::kernels {

struct EnrichedEdgeBatch {
  ElementType type;
  std::int64_t count;
  const int* edges;             // #edges x 4: plus element, plus local edge, minus element (-1), minus local edge
  const double* edge_size;      // h^e
  double penalty;               // eta; eta^e = eta / h^e
  int quadrature_points;        // Gauss points per merged segment
  const int* connectivity;      // #elements x npe
  const double* positions;      // rest, #nodes x 3
  const ShellSection* sections; // per element
  const EnrichedElementBatch* elements;
  const int* enriched_index;    // per mesh element: its index in *elements, or -1
};

struct EdgeQuadrature {
  const std::int64_t* start;  // #edges + 1
  const double* points;       // (t, weight) per point
};

void enriched_edge_quadrature(const EnrichedEdgeBatch& batch, const EnrichedQuadratureOptions& options,
                              std::vector<std::int64_t>& start, std::vector<double>& points,
                              Execution execution = Execution::parallel);

// Global node of each local slot (2W entries, -1 for unused slots).
void enriched_edge_global_nodes(const EnrichedEdgeBatch& batch, std::int64_t edge, int* global_nodes);

// The edges' compact local layout: edge e has widths[e] local functions, its blocks from
// block index block_start[e] ((i, j) at block_start[e] + i widths[e] + j), its force rows
// from function_start[e] (#edges + 1 entries each): BlockSourceFamily::widths's layout.
struct EnrichedEdgeLocalLayout {
  std::vector<int> widths;
  std::vector<std::int64_t> function_start, block_start;
};
EnrichedEdgeLocalLayout enriched_edge_local_layout(const EnrichedEdgeBatch& batch);
// Global node of each local function of the edge in that layout (widths[e] entries).
void enriched_edge_local_global_nodes(const EnrichedEdgeBatch& batch, std::int64_t edge, int* global_nodes);

void enriched_edge_stiffness(const EnrichedEdgeBatch& batch, const EdgeQuadrature& quadrature,
                             const double* rotations, double* blocks, double* forces,
                             Execution execution = Execution::parallel);

// The corotated blocks and forces with each point's rotation (that of
// enriched_edge_rotations) formed in the stiffness pass from the sides it evaluates anyway:
// one evaluation of both sides per point instead of two (fracture: ~4 ms a step). Bitwise
// enriched_edge_rotations followed by enriched_edge_stiffness.
void enriched_edge_corotated_stiffness(const EnrichedEdgeBatch& batch, const EdgeQuadrature& quadrature,
                                       const double* current, double* blocks, double* forces,
                                       Execution execution = Execution::parallel);

// The rest data of both sides at every edge point that the corotated stiffness reads (rest
// frame, tangent, the side's local basis's first derivatives): they depend on the basis
// alone, so a model computes them once per basis instead of evaluating both sides at every
// point in every step (the slinky: 64 % of the pass; fracture: 2 ms a step on 1 thread).
// counts: per edge, the basis functions of side 0 and side 1 (0: no minus side); offset: per
// edge, its first double in data (a point's records follow each other, side 0 first, each
// 15 + 2 count doubles).
struct EnrichedEdgeRestSides {
  std::vector<int> counts;
  std::vector<std::int64_t> offset;
  std::vector<double> data;
};
void enriched_edge_rest_sides(const EnrichedEdgeBatch& batch, const EdgeQuadrature& quadrature,
                              EnrichedEdgeRestSides& out, Execution execution = Execution::parallel);

// enriched_edge_corotated_stiffness with the sides read from rest_sides (made by
// enriched_edge_rest_sides for this batch and quadrature): bitwise the same blocks and forces.
void enriched_edge_corotated_stiffness(const EnrichedEdgeBatch& batch, const EdgeQuadrature& quadrature,
                                       const EnrichedEdgeRestSides& rest_sides, const double* current,
                                       double* blocks, double* forces, Execution execution = Execution::parallel);

// Rotation of the edge frame (tangent, averaged normal) from rest to current, the current
// frame taken from each side's whole basis; the identity on clamped boundary edges (as
// shell_edge_rotations). current: #(nodes + virtual nodes) x 3.
void enriched_edge_rotations(const EnrichedEdgeBatch& batch, const EdgeQuadrature& quadrature,
                             const double* current, double* rotations, Execution execution = Execution::parallel);

}  // namespace dgtex::kernels
