#include "dgtex/kernels/shell_edge_kernel.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "dgtex/kernels/shell_point.h"
#include "dgtex/kernels/edge_frame.h"
#include "dgtex/kernels/low_rank_block.h"
#include "dgtex/kernels/vec3.h"
#include "shell_point_rows.h"

namespace dgtex::kernels {
namespace {

// Most Gauss points per edge (gauss_legendre supports 1..5).
constexpr int max_edge_points = 5;
constexpr int max_edge_dofs = 2 * 3 * max_element_nodes;
constexpr int max_local_edges = 4;

// Shape values along every local edge, in both directions (the plus element traverses an
// edge at t, the minus element at -t), at every Gauss point: the same for all edges.
struct EdgeRuleShapes {
  LineRule rule;
  ShapeValues shape[max_local_edges][2][max_edge_points];
  double dxi[max_local_edges][2][2];  // dxi/dt per local edge and direction
  EdgeRuleShapes(ElementType type, int points) : rule(gauss_legendre(points)) {
    const int edges = type == ElementType::quad8 ? 4 : 3;
    for (int k = 0; k < edges; ++k)
      for (int direction = 0; direction < 2; ++direction)
        for (int q = 0; q < rule.count; ++q) {
          double xi[2];
          local_edge_point(type, k, direction == 0 ? rule.t[q] : -rule.t[q], xi, dxi[k][direction]);
          evaluate_shape(type, xi[0], xi[1], shape[k][direction][q]);
        }
  }
};

// One side of an edge at Gauss point q (the minus side runs reversed).
struct Side {
  const ShapeValues* shape;
  RestPoint point;
  double tangent[3];  // dphi/dt
};

void evaluate_side(const EdgeBatch& b, const EdgeRuleShapes& shapes, int element, int local_edge, int direction,
                   int q, Side& s) {
  const int npe = nodes_per_element(b.type);
  s.shape = &shapes.shape[local_edge][direction][q];
  evaluate_rest_point(*s.shape, b.connectivity + static_cast<long>(element) * npe, b.positions, s.point);
  tangent_along(s.point, shapes.dxi[local_edge][direction], s.tangent);
}

// The local basis of an edge: slot of each (side, node) and global node of each slot.
// Separate: the plus element's npe functions, then the minus element's (2 npe slots).
// Merged: one slot per distinct global node (the functions of a node shared by both
// sides summed), plus nodes first, then the minus nodes not among them.
struct EdgeBasis {
  int count = 0;
  int slot[2][max_element_nodes];
  int node[2 * max_element_nodes];
};

void edge_basis(const EdgeBatch& b, std::int64_t e, bool merged, EdgeBasis& basis) {
  const int npe = nodes_per_element(b.type);
  const int* ed = b.edges + 4 * e;
  basis.count = 0;
  for (int side = 0; side < (ed[2] >= 0 ? 2 : 1); ++side) {
    const int* nodes = b.connectivity + static_cast<long>(ed[2 * side]) * npe;
    for (int a = 0; a < npe; ++a) {
      int found = -1;
      if (merged && side == 1)
        for (int i = 0; i < npe && found < 0; ++i)
          if (basis.node[i] == nodes[a]) found = i;
      if (found < 0) {
        found = merged ? basis.count : side * npe + a;
        basis.node[found] = nodes[a];
        basis.count = std::max(basis.count, found + 1);
      }
      basis.slot[side][a] = found;
    }
  }
}

// Per-edge constants of the edge terms: the penalty eta^e times the mean bending rigidity,
// and the weight of each side's moment in the average (0 for penalty-only coupling).
struct EdgeCoefficients {
  double dm_plus, dm_minus, penalty, average;
};

EdgeCoefficients edge_coefficients(const EdgeBatch& b, std::int64_t e) {
  const int* ed = b.edges + 4 * e;
  const bool interior = ed[2] >= 0;
  const ShellSection& sp = b.sections[ed[0]];
  const ShellSection& sm = b.sections[interior ? ed[2] : ed[0]];
  EdgeCoefficients c;
  c.dm_plus = bending_rigidity(sp.youngs_modulus, sp.poisson_ratio, sp.thickness);
  c.dm_minus = bending_rigidity(sm.youngs_modulus, sm.poisson_ratio, sm.thickness);
  c.penalty = b.penalty / b.edge_size[e] * (interior ? 0.5 * (c.dm_plus + c.dm_minus) : c.dm_plus);
  // Penalty-only coupling drops the moment rows M (consistency and symmetry terms).
  c.average = b.penalty_only ? 0.0 : (interior ? 0.5 : 1.0);
  return c;
}

// The rest rows of Gauss point q of edge e over its local basis: G = [[g]] (jump of the
// hinge rotation measure) and M = {m_nunu} (average normal bending moment), 3 columns per
// basis function (zero beyond basis.count), and the length weight ds. They depend on the
// rest geometry only; the corotation rotates them (R G, R M).
void edge_point_rows(const EdgeBatch& b, const EdgeRuleShapes& shapes, std::int64_t e, const EdgeBasis& basis,
                     const EdgeCoefficients& co, int q, double& ds, double (*G)[3], double (*M)[3]) {
  const int npe = nodes_per_element(b.type);
  const int* ed = b.edges + 4 * e;
  const bool interior = ed[2] >= 0;
  const ShellSection& sp = b.sections[ed[0]];
  const ShellSection& sm = b.sections[interior ? ed[2] : ed[0]];
  Side plus, minus;
  evaluate_side(b, shapes, ed[0], ed[1], 0, q, plus);
  if (interior) evaluate_side(b, shapes, ed[2], ed[3], 1, q, minus);
  ds = std::sqrt(dot3(plus.tangent, plus.tangent)) * shapes.rule.weight[q];
  double tau[3] = {plus.tangent[0], plus.tangent[1], plus.tangent[2]};
  normalize3(tau);
  for (int i = 0; i < 2 * npe; ++i)
    for (int c = 0; c < 3; ++c) G[i][c] = M[i][c] = 0;
  for (int side = 0; side < (interior ? 2 : 1); ++side) {
    const Side& s = side == 0 ? plus : minus;
    const double nu_p = (side == 0 ? sp : sm).poisson_ratio;
    const double dm = side == 0 ? co.dm_plus : co.dm_minus;
    const double sign = side == 0 ? 1.0 : -1.0;
    double nu_vec[3], e1[3], e2[3];
    cross3(s.point.t0, tau, nu_vec);
    frame_along(s.point, tau, e1, e2);  // e1 = tau, e2 = t0 x tau = nu
    fast_rows::PointFrame frame;
    fast_rows::make_point_frame(s.point, e1, e2, frame);
    for (int a = 0; a < npe; ++a) {
      double T[9], Bb[9];
      fast_rows::normal_change(s.point, frame, s.shape->dN[a], T);
      fast_rows::bending(s.point, frame, s.shape->d2N[a], T, Bb);
      const int i = basis.slot[side][a];
      for (int c = 0; c < 3; ++c) {
        G[i][c] += sign * (nu_vec[0] * T[0 * 3 + c] + nu_vec[1] * T[1 * 3 + c] + nu_vec[2] * T[2 * 3 + c]);
        // m_nunu = D (nu rho_11 + rho_22) in the frame (tau, nu).
        M[i][c] += co.average * dm * (nu_p * Bb[0 * 3 + c] + Bb[1 * 3 + c]);
      }
    }
  }
}

// G . d and M . d over the edge's local basis for d = X0 - R^T X0 (the rest positions minus
// their rotation): the corotational corrective force's projections.
void corrective_projections(const EdgeBatch& b, const EdgeBasis& basis, const double* R, const double (*G)[3],
                            const double (*M)[3], double& gd, double& md) {
  for (int i = 0; i < basis.count; ++i) {
    const double* x = b.positions + 3 * static_cast<long>(basis.node[i]);
    for (int k = 0; k < 3; ++k) {
      const double d = x[k] - (R[0 * 3 + k] * x[0] + R[1 * 3 + k] * x[1] + R[2 * 3 + k] * x[2]);
      gd += G[i][k] * d;
      md += M[i][k] * d;
    }
  }
}

// K = sum over points of ds (penalty G G^T + M G^T + G M^T) with G, M the rows of the jump
// and the average moment over the edge's local basis, evaluated as P G^T + Q M^T per point
// (P = ds (penalty G + M), Q = ds G; rows stacked as Ls = [P; Q], Rs = [G; M]): 2 nq (3n)^2
// multiply-adds per edge, n = the local basis size: 2 npe separate, 13 for merged quad8
// interior edges (3 shared nodes), 0.66x the work of the separate basis.
void edge_stiffness(const EdgeBatch& b, const EdgeRuleShapes& shapes, std::int64_t e, bool merged,
                    const double* rotations, double* blocks, double* forces) {
  const int npe = nodes_per_element(b.type);
  const int nb = 2 * npe;
  EdgeBasis basis;
  edge_basis(b, e, merged, basis);
  const int n = basis.count;
  double* K = blocks + e * nb * nb * 9;
  double* f = forces ? forces + e * nb * 3 : nullptr;
  if (f)
    for (int i = 0; i < nb * 3; ++i) f[i] = 0;

  const EdgeCoefficients co = edge_coefficients(b, e);
  const double penalty = co.penalty;
  const LineRule& rule = shapes.rule;

  // Per point: Ls = [P; Q] and Rs = [G; M] over (basis function, component).
  alignas(64) double Ls[2 * max_edge_points][max_edge_dofs], Rs[2 * max_edge_points][max_edge_dofs];
  for (int q = 0; q < rule.count; ++q) {
    double ds;
    double G[2 * max_element_nodes][3], M[2 * max_element_nodes][3];
    edge_point_rows(b, shapes, e, basis, co, q, ds, G, M);
    const double* R = rotations ? rotations + (e * rule.count + q) * 9 : nullptr;
    double gd = 0, md = 0;  // G . d and M . d for the corrective force, d = X0 - R^T X0
    if (R && f) corrective_projections(b, basis, R, G, M, gd, md);
    if (R) {
      for (int i = 0; i < n; ++i) {
        double g2[3], m2[3];
        for (int c = 0; c < 3; ++c) {
          g2[c] = G[i][0] * R[c * 3 + 0] + G[i][1] * R[c * 3 + 1] + G[i][2] * R[c * 3 + 2];
          m2[c] = M[i][0] * R[c * 3 + 0] + M[i][1] * R[c * 3 + 1] + M[i][2] * R[c * 3 + 2];
        }
        for (int c = 0; c < 3; ++c) G[i][c] = g2[c], M[i][c] = m2[c];
      }
    }
    double* P = Ls[2 * q];
    double* Q = Ls[2 * q + 1];
    double* Gr = Rs[2 * q];
    double* Mr = Rs[2 * q + 1];
    for (int i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        Gr[3 * i + c] = G[i][c];
        Mr[3 * i + c] = M[i][c];
        P[3 * i + c] = ds * (penalty * G[i][c] + M[i][c]);
        Q[3 * i + c] = ds * G[i][c];
      }
    if (R && f)
      for (int i = 0; i < n; ++i)
        for (int r = 0; r < 3; ++r) f[i * 3 + r] += ds * (penalty * G[i][r] * gd + M[i][r] * gd + G[i][r] * md);
  }
  // Each block sums its points in registers and is stored once, in order (measured faster
  // for these short sums, 2 nq terms, than the tiled upper-triangle product of the element
  // kernel, whose write-out dominates here).
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      double blk[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
      for (int q = 0; q < rule.count; ++q) {
        const double* P = Ls[2 * q] + 3 * i;
        const double* Q = Ls[2 * q + 1] + 3 * i;
        const double* G = Rs[2 * q] + 3 * j;
        const double* M = Rs[2 * q + 1] + 3 * j;
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) blk[r * 3 + c] += P[r] * G[c] + Q[r] * M[c];
      }
      double* out = K + (i * nb + j) * 9;
      for (int k = 0; k < 9; ++k) out[k] = blk[k];
    }
  if (!merged)  // the separate layout is complete: zero blocks outside the used basis
    for (int i = 0; i < nb; ++i)
      for (int j = 0; j < nb; ++j)
        if (i >= n || j >= n)
          for (int k = 0; k < 9; ++k) K[(i * nb + j) * 9 + k] = 0;
}

// Rest rows of every point of edge e (shell_edge_rest_rows layout) at `rows`.
void edge_rest_rows(const EdgeBatch& b, const EdgeRuleShapes& shapes, std::int64_t e, double* rows) {
  const int nb = 2 * nodes_per_element(b.type);
  EdgeBasis basis;
  edge_basis(b, e, true, basis);
  const EdgeCoefficients co = edge_coefficients(b, e);
  const std::int64_t stride = 2 + 6 * nb;
  for (int q = 0; q < shapes.rule.count; ++q) {
    double* row = rows + q * stride;
    double G[2 * max_element_nodes][3], M[2 * max_element_nodes][3];
    edge_point_rows(b, shapes, e, basis, co, q, row[0], G, M);
    row[1] = co.penalty;
    for (int i = 0; i < nb; ++i)
      for (int c = 0; c < 3; ++c) {
        row[2 + 3 * i + c] = G[i][c];
        row[2 + 3 * nb + 3 * i + c] = M[i][c];
      }
  }
}

// Factors (and corrective forces) of edge e from its rest rows `rows`: the arithmetic of
// edge_stiffness after its rows are evaluated, so products of the factors equal its blocks.
void edge_factors(const EdgeBatch& b, std::int64_t e, const double* rows, const double* rotations, double* factors,
                  double* forces) {
  const int nb = 2 * nodes_per_element(b.type);
  const int nq = b.quadrature_points, rank = 2 * nq;
  EdgeBasis basis;
  edge_basis(b, e, true, basis);
  const int n = basis.count;
  double* F = factors + e * nb * 2 * rank * 3;
  double* f = forces ? forces + e * nb * 3 : nullptr;
  if (f)
    for (int i = 0; i < nb * 3; ++i) f[i] = 0;
  const std::int64_t stride = 2 + 6 * nb;
  for (int q = 0; q < nq; ++q) {
    const double* row = rows + q * stride;
    const double ds = row[0], penalty = row[1];
    const double (*G)[3] = reinterpret_cast<const double (*)[3]>(row + 2);
    const double (*M)[3] = reinterpret_cast<const double (*)[3]>(row + 2 + 3 * nb);
    const double* R = rotations ? rotations + (e * nq + q) * 9 : nullptr;
    double gd = 0, md = 0;  // G . d and M . d for the corrective force, d = X0 - R^T X0
    if (R && f) corrective_projections(b, basis, R, G, M, gd, md);
    for (int i = 0; i < n; ++i) {
      double g[3], m[3];
      for (int c = 0; c < 3; ++c) {
        g[c] = R ? G[i][0] * R[c * 3 + 0] + G[i][1] * R[c * 3 + 1] + G[i][2] * R[c * 3 + 2] : G[i][c];
        m[c] = R ? M[i][0] * R[c * 3 + 0] + M[i][1] * R[c * 3 + 1] + M[i][2] * R[c * 3 + 2] : M[i][c];
      }
      double* L = F + i * 2 * rank * 3;
      double* Rt = L + rank * 3;
      for (int c = 0; c < 3; ++c) {
        L[(2 * q) * 3 + c] = ds * (penalty * g[c] + m[c]);
        L[(2 * q + 1) * 3 + c] = ds * g[c];
        Rt[(2 * q) * 3 + c] = g[c];
        Rt[(2 * q + 1) * 3 + c] = m[c];
      }
      if (R && f)
        for (int r = 0; r < 3; ++r) f[i * 3 + r] += ds * (penalty * g[r] * gd + m[r] * gd + g[r] * md);
    }
  }
}

}  // namespace

void shell_edge_stiffness(const EdgeBatch& batch, const double* rotations, double* blocks, double* forces,
                          Execution execution) {
  const EdgeRuleShapes shapes(batch.type, batch.quadrature_points);
  forall(
      batch.count, [&](std::int64_t e) { edge_stiffness(batch, shapes, e, false, rotations, blocks, forces); },
      execution);
}

void shell_edge_stiffness_merged(const EdgeBatch& batch, const double* rotations, double* blocks, double* forces,
                                 Execution execution) {
  const EdgeRuleShapes shapes(batch.type, batch.quadrature_points);
  forall(
      batch.count, [&](std::int64_t e) { edge_stiffness(batch, shapes, e, true, rotations, blocks, forces); },
      execution);
}

std::int64_t shell_edge_rest_row_stride(const EdgeBatch& batch) { return 2 + 12 * nodes_per_element(batch.type); }

std::int64_t shell_edge_factor_stride(const EdgeBatch& batch) {
  return 2 * nodes_per_element(batch.type) * 2 * shell_edge_factor_rank(batch) * 3;
}

void shell_edge_rest_rows(const EdgeBatch& batch, double* rows, Execution execution) {
  const EdgeRuleShapes shapes(batch.type, batch.quadrature_points);
  const std::int64_t per_edge = batch.quadrature_points * shell_edge_rest_row_stride(batch);
  forall(batch.count, [&](std::int64_t e) { edge_rest_rows(batch, shapes, e, rows + e * per_edge); }, execution);
}

void shell_edge_factors(const EdgeBatch& batch, const double* rest_rows, const double* rotations, double* factors,
                        double* forces, Execution execution) {
  const std::int64_t per_edge = batch.quadrature_points * shell_edge_rest_row_stride(batch);
  forall(
      batch.count,
      [&](std::int64_t e) { edge_factors(batch, e, rest_rows + e * per_edge, rotations, factors, forces); },
      execution);
}

void shell_edge_factors_reference(const EdgeBatch& batch, const double* rotations, double* factors, double* forces) {
  const EdgeRuleShapes shapes(batch.type, batch.quadrature_points);
  std::vector<double> rows(batch.quadrature_points * shell_edge_rest_row_stride(batch));
  for (std::int64_t e = 0; e < batch.count; ++e) {
    edge_rest_rows(batch, shapes, e, rows.data());
    edge_factors(batch, e, rows.data(), rotations, factors, forces);
  }
}

void shell_edge_blocks_from_factors(const EdgeBatch& batch, const double* factors, double* blocks) {
  const int nb = 2 * nodes_per_element(batch.type);
  const int rank = shell_edge_factor_rank(batch);
  for (std::int64_t e = 0; e < batch.count; ++e) {
    int nodes[2 * max_element_nodes];
    const int n = shell_edge_merged_nodes(batch, e, nodes);
    const double* F = factors + e * shell_edge_factor_stride(batch);
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j)
        low_rank_block(rank, F + i * 2 * rank * 3, F + j * 2 * rank * 3 + rank * 3, blocks + ((e * nb + i) * nb + j) * 9);
  }
}

int shell_edge_merged_nodes(const EdgeBatch& batch, std::int64_t edge, int* nodes) {
  EdgeBasis basis;
  edge_basis(batch, edge, true, basis);
  std::copy_n(basis.node, basis.count, nodes);
  return basis.count;
}

void shell_edge_rotations(const EdgeBatch& b, const double* current, double* rotations, Execution execution) {
  const LineRule rule = gauss_legendre(b.quadrature_points);
  forall(
      b.count,
      [&](std::int64_t e) {
        const int* ed = b.edges + 4 * e;
        const bool interior = ed[2] >= 0;
        if (!interior) {
          // A clamped boundary edge holds the normal at its prescribed rest value, fixed in
          // space: turning the clamp's terms with the element's own frame would let the
          // element rotate about the edge at no cost (a clamped cantilever hinged, and even
          // under 1 % of gravity the demo cantilever sagged 4.1x the linear deflection). R = I.
          for (int q = 0; q < rule.count; ++q)
            for (int i = 0; i < 9; ++i) rotations[(e * rule.count + q) * 9 + i] = i % 4 == 0 ? 1.0 : 0.0;
          return;
        }
        const int npe = nodes_per_element(b.type);
        for (int q = 0; q < rule.count; ++q) {
          // Shape values once per side; the rest and current frames share them.
          fast_rows::SurfaceFrame rest_side[2], current_side[2];
          double dxi_plus[2] = {0, 0};
          for (int side = 0; side < 2; ++side) {
            double xi[2], dxi[2];
            local_edge_point(b.type, ed[2 * side + 1], side == 0 ? rule.t[q] : -rule.t[q], xi, dxi);
            if (side == 0) dxi_plus[0] = dxi[0], dxi_plus[1] = dxi[1];
            ShapeValues shape;
            evaluate_shape(b.type, xi[0], xi[1], shape);
            const int* nodes = b.connectivity + static_cast<long>(ed[2 * side]) * npe;
            fast_rows::evaluate_surface_frame(shape, nodes, b.positions, rest_side[side]);
            fast_rows::evaluate_surface_frame(shape, nodes, current, current_side[side]);
          }
          double rest[9], cur[9];
          for (int k = 0; k < 2; ++k) {
            const fast_rows::SurfaceFrame* sides = k == 0 ? rest_side : current_side;
            double tangent[3];
            for (int d = 0; d < 3; ++d) tangent[d] = sides[0].a1[d] * dxi_plus[0] + sides[0].a2[d] * dxi_plus[1];
            edge_frame(tangent, sides[0].t0, sides[1].t0, k == 0 ? rest : cur);
          }
          // R = Cur * Rest^T maps the rest frame onto the current one.
          double* R = rotations + (e * rule.count + q) * 9;
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
              R[i * 3 + j] = cur[i * 3 + 0] * rest[j * 3 + 0] + cur[i * 3 + 1] * rest[j * 3 + 1] + cur[i * 3 + 2] * rest[j * 3 + 2];
        }
      },
      execution);
}

}  // namespace dgtex::kernels
