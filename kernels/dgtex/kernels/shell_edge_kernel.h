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

// The plain serial reference form of shell_edge_stiffness (per point, block by block);
// equal to it to round-off (~1e-15 relative), not bitwise.
void shell_edge_stiffness_reference(const EdgeBatch& batch, const double* rotations, double* blocks, double* forces);

// Rotation of the edge frame (tangent, averaged normal) from rest to current positions.
void shell_edge_rotations(const EdgeBatch& batch, const double* current_positions, double* rotations,
                          Execution execution = Execution::parallel);

}  // namespace dgtex::kernels
