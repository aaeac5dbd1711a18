#pragma once
// Edge terms of the DG Kirchhoff-Love shell (shell report eq. 14/37, Noels & Radovitzky):
// on interior edges the jump of the normal rotation is penalised and the consistency and
// symmetry terms couple it to the average bending moment; on clamped boundary edges the
// same terms hold the normal against its prescribed (rest) value.
//
// Departure from eq. 37, on purpose: the terms act on the hinge component
//   g = dt(u) . nu   (nu = t0 x tau: in-plane normal of the edge, pointing into K+)
// of each side's normal change, with the conjugate moment m_nunu. The other component,
// dt . tau = -u,tau . t0, has jump -u,tau . [[t0]] for C0 fields: zero on flat edges, but on
// the kinked edges of a curved mesh it is non-zero for a rigid rotation, so keeping it
// would give rigid modes strain energy. With g both sides measure the rotation about the
// common tangent tau, which a rigid motion leaves equal.
//
// Per edge e: edges[4e..4e+3] = (plus element, plus local edge, minus element, minus local
// edge); the minus element is -1 on boundary edges. The plus element traverses the edge in
// its own local direction (it lies on the left); the minus element traverses it reversed.
// Local basis order of an edge: the plus element's npe nodes, then the minus element's.
// Outputs: blocks #edges x (2 npe)^2 x 9, forces #edges x 2 npe x 3 (minus half zero on
// boundary edges). Rotations (optional): #edges x nq x 9.
// Kernel conventions (dgtex/kernels/forall.h): arrays are the caller's, batch/view structs
// only point into them, nothing is kept after a call; thread-safe on distinct outputs.
// Units: consistent (SI: positions m, E Pa, h m, density kg/m^3; blocks N/m, forces N, mass kg).
#include <cstdint>

#include "dgtex/kernels/forall.h"
#include "dgtex/kernels/shape_functions.h"
#include "dgtex/kernels/shell_element_kernel.h"

namespace dgtex::kernels {

struct EdgeBatch {
  ElementType type;
  std::int64_t count;
  const int* edges;             // #edges x 4
  const double* edge_size;      // h^e per edge (report eq. 16)
  double penalty;               // eta (eq. 15): eta^e = eta / h^e
  int quadrature_points;        // Gauss points along the edge
  const int* connectivity;      // #elements x npe
  const double* positions;      // rest, #nodes x 3
  const ShellSection* sections; // per element
  // Penalty-only coupling (Babuska-Zlamal style): drop the consistency and symmetry terms
  // and keep only the penalty on the jump. Not consistent: converges only as the penalty
  // grows, at the price of conditioning (README, failure modes). The default keeps them.
  bool penalty_only;
};

void shell_edge_stiffness(const EdgeBatch& batch, const double* rotations, double* blocks, double* forces,
                          Execution execution = Execution::parallel);

// shell_edge_stiffness over each edge's distinct nodes: where the plus and minus elements
// share a node, its two basis functions are merged into one (the sum of their rows), so
// the assembled matrix is the same (to round-off) with ~2/3 of the work and of the
// blocks (13 x 13 instead of 16 x 16 for quad8 interior edges). Merged local basis of edge
// e: shell_edge_merged_nodes (the plus element's npe nodes, then the minus element's nodes
// that are not among them, in its order). Same output slots as shell_edge_stiffness:
// block (i, j) at (e * (2 npe)^2 + i * 2 npe + j) * 9 and force i at (e * 2 npe + i) * 3,
// for i, j < the merged count; blocks beyond it are not written (forces beyond are zero).
void shell_edge_stiffness_merged(const EdgeBatch& batch, const double* rotations, double* blocks, double* forces,
                                 Execution execution = Execution::parallel);
// Global nodes of edge e's merged local basis (nodes: room for 2 npe); returns their count.
int shell_edge_merged_nodes(const EdgeBatch& batch, std::int64_t edge, int* nodes);

// shell_edge_stiffness_merged in factored form, with its rest-geometry part computed once.
// Per point q the edge stiffness is P G^T + Q M^T (rank 2 over the local basis), with G, M
// the jump and average-moment rows, which depend on the rest geometry only (the corotation
// rotates them: R G, R M), and P = ds (penalty G + M), Q = ds G. So:
//  - shell_edge_rest_rows evaluates, once per model, per (edge e, point q) at
//    (e nq + q) * shell_edge_rest_row_stride: ds, penalty eta^e D, G (2 npe x 3), M (2 npe x 3)
//    over the merged basis (slots beyond its count zero);
//  - shell_edge_factors rotates them per step and writes, per edge (at e *
//    shell_edge_factor_stride) and merged slot i (at i * 2 rank * 3), the left factor
//    L_i = [P_0, Q_0, P_1, Q_1, ...] (rank = 2 nq 3-vectors) and then the right factor
//    R_i = [G_0, M_0, G_1, M_1, ...]; local block (i, j) = low_rank_block(rank, L_i, R_j)
//    (dgtex/kernels/low_rank_block.h), bitwise shell_edge_stiffness_merged's block. Forces
//    as shell_edge_stiffness_merged's, bitwise. ~5x less output than the 13 x 13 blocks.
// Slots at or beyond an edge's merged count are not written.
inline int shell_edge_factor_rank(const EdgeBatch& batch) { return 2 * batch.quadrature_points; }
std::int64_t shell_edge_rest_row_stride(const EdgeBatch& batch);  // doubles per edge point
std::int64_t shell_edge_factor_stride(const EdgeBatch& batch);    // doubles per edge
void shell_edge_rest_rows(const EdgeBatch& batch, double* rest_rows, Execution execution = Execution::parallel);
void shell_edge_factors(const EdgeBatch& batch, const double* rest_rows, const double* rotations, double* factors,
                        double* forces, Execution execution = Execution::parallel);
// The serial reference form of shell_edge_factors: rest rows evaluated per edge as it goes
// (no cache); bitwise equal to shell_edge_rest_rows + shell_edge_factors.
void shell_edge_factors_reference(const EdgeBatch& batch, const double* rotations, double* factors, double* forces);
// Expands factors into shell_edge_stiffness_merged's block layout (merged slots only).
void shell_edge_blocks_from_factors(const EdgeBatch& batch, const double* factors, double* blocks);

// The plain serial reference form of shell_edge_stiffness (per point, block by block);
// equal to it to round-off (~1e-15 relative), not bitwise.
void shell_edge_stiffness_reference(const EdgeBatch& batch, const double* rotations, double* blocks, double* forces);

// Rotation of the edge frame (tangent, averaged normal) from rest to current positions on
// interior edges; the identity on clamped boundary edges, whose prescribed normal is fixed in
// space (a rotation there would let the clamped element turn about the edge at no cost).
void shell_edge_rotations(const EdgeBatch& batch, const double* current_positions, double* rotations,
                          Execution execution = Execution::parallel);

}  // namespace dgtex::kernels
