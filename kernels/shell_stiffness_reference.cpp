// The straightforward serial reference forms of the shell stiffness kernels: per
// quadrature point, the strain rows from dgtex/kernels/shell_point.h and every 3x3 block
// accumulated in place, exactly as the shell report writes the sums. The optimised
// kernels (shell_element_kernel.cpp, shell_edge_kernel.cpp) are tested against these.
#include <cmath>

#include "dgtex/kernels/shell_edge_kernel.h"
#include "dgtex/kernels/shell_element_kernel.h"
#include "dgtex/kernels/shell_point.h"
#include "dgtex/kernels/vec3.h"
#include "plane_stress.h"

namespace dgtex::kernels {
namespace {

void element_stiffness_reference(const ElementBatch& b, std::int64_t e, const double* rotations, double* blocks,
                       double* forces) {
  const int npe = nodes_per_element(b.type);
  const int* nodes = b.connectivity + e * npe;
  const ShellSection& sec = b.sections[e];
  const double nu = sec.poisson_ratio;
  const double dn = membrane_rigidity(sec.youngs_modulus, nu, sec.thickness);
  const double dm = bending_rigidity(sec.youngs_modulus, nu, sec.thickness);
  const QuadratureRule rule = element_quadrature(b.type);

  double* K = blocks + e * npe * npe * 9;
  for (int i = 0; i < npe * npe * 9; ++i) K[i] = 0;
  double* f = forces ? forces + e * npe * 3 : nullptr;
  if (f)
    for (int i = 0; i < npe * 3; ++i) f[i] = 0;

  for (int q = 0; q < rule.count; ++q) {
    ShapeValues s;
    evaluate_shape(b.type, rule.xi1[q], rule.xi2[q], s);
    RestPoint p;
    evaluate_rest_point(s, nodes, b.positions, p);
    double e1[3], e2[3];
    frame_along(p, p.a1, e1, e2);
    const double w = rule.weight[q] * p.j0;

    double Bm[max_element_nodes][9], Bb[max_element_nodes][9];
    for (int a = 0; a < npe; ++a) {
      membrane_rows(p, e1, e2, s.dN[a], Bm[a]);
      bending_rows(p, e1, e2, s.dN[a], s.d2N[a], Bb[a]);
    }
    const double* R = rotations ? rotations + (e * rule.count + q) * 9 : nullptr;
    double strain_m[3] = {0, 0, 0}, strain_b[3] = {0, 0, 0};
    if (R && f) {
      // Strain of the corrective term: B (X0 - R^T X0).
      for (int a = 0; a < npe; ++a) {
        const double* x = b.positions + 3 * static_cast<long>(nodes[a]);
        double d[3];
        for (int k = 0; k < 3; ++k) d[k] = x[k] - (R[0 * 3 + k] * x[0] + R[1 * 3 + k] * x[1] + R[2 * 3 + k] * x[2]);
        for (int r = 0; r < 3; ++r) {
          strain_m[r] += Bm[a][r * 3 + 0] * d[0] + Bm[a][r * 3 + 1] * d[1] + Bm[a][r * 3 + 2] * d[2];
          strain_b[r] += Bb[a][r * 3 + 0] * d[0] + Bb[a][r * 3 + 1] * d[1] + Bb[a][r * 3 + 2] * d[2];
        }
      }
    }
    if (R) {
      for (int a = 0; a < npe; ++a) {
        double tmp[9];
        rotate_rows(Bm[a], R, tmp);
        for (int i = 0; i < 9; ++i) Bm[a][i] = tmp[i];
        rotate_rows(Bb[a], R, tmp);
        for (int i = 0; i < 9; ++i) Bb[a][i] = tmp[i];
      }
    }
    // Stress-like products D B_b, one column (x, y, z of node b) at a time.
    double DBm[max_element_nodes][9], DBb[max_element_nodes][9];
    for (int a = 0; a < npe; ++a)
      for (int c = 0; c < 3; ++c) {
        const double vm[3] = {Bm[a][0 * 3 + c], Bm[a][1 * 3 + c], Bm[a][2 * 3 + c]};
        const double vb[3] = {Bb[a][0 * 3 + c], Bb[a][1 * 3 + c], Bb[a][2 * 3 + c]};
        double om[3], ob[3];
        apply_plane_stress(nu, dn, vm, om);
        apply_plane_stress(nu, dm, vb, ob);
        for (int r = 0; r < 3; ++r) DBm[a][r * 3 + c] = om[r], DBb[a][r * 3 + c] = ob[r];
      }
    for (int a = 0; a < npe; ++a)
      for (int bb = 0; bb < npe; ++bb) {
        double* blk = K + (a * npe + bb) * 9;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) {
            double v = 0;
            for (int r = 0; r < 3; ++r) v += Bm[a][r * 3 + i] * DBm[bb][r * 3 + j] + Bb[a][r * 3 + i] * DBb[bb][r * 3 + j];
            blk[i * 3 + j] += w * v;
          }
      }
    if (R && f) {
      double sm[3], sb[3];
      apply_plane_stress(nu, dn, strain_m, sm);
      apply_plane_stress(nu, dm, strain_b, sb);
      add_corrective_force(npe, Bm, Bb, sm, sb, w, f);
    }
  }
}

// One side of an edge at parameter t (in the plus element's direction).
struct Side {
  ShapeValues shape;
  RestPoint point;
  double tangent[3];  // dphi/dt
};

void evaluate_side(const EdgeBatch& b, int element, int local_edge, double t, const double* positions, Side& s) {
  const int npe = nodes_per_element(b.type);
  double xi[2], dxi[2];
  local_edge_point(b.type, local_edge, t, xi, dxi);
  evaluate_shape(b.type, xi[0], xi[1], s.shape);
  evaluate_rest_point(s.shape, b.connectivity + static_cast<long>(element) * npe, positions, s.point);
  tangent_along(s.point, dxi, s.tangent);
}

void edge_stiffness_reference(const EdgeBatch& b, std::int64_t e, const double* rotations, double* blocks, double* forces) {
  const int npe = nodes_per_element(b.type);
  const int nb = 2 * npe;
  const int* ed = b.edges + 4 * e;
  const bool interior = ed[2] >= 0;
  double* K = blocks + e * nb * nb * 9;
  for (int i = 0; i < nb * nb * 9; ++i) K[i] = 0;
  double* f = forces ? forces + e * nb * 3 : nullptr;
  if (f)
    for (int i = 0; i < nb * 3; ++i) f[i] = 0;

  const ShellSection& sp = b.sections[ed[0]];
  const ShellSection& sm = b.sections[interior ? ed[2] : ed[0]];
  const double dm_plus = bending_rigidity(sp.youngs_modulus, sp.poisson_ratio, sp.thickness);
  const double dm_minus = bending_rigidity(sm.youngs_modulus, sm.poisson_ratio, sm.thickness);
  const double penalty = b.penalty / b.edge_size[e] * (interior ? 0.5 * (dm_plus + dm_minus) : dm_plus);
  // Penalty-only coupling drops the moment rows M (consistency and symmetry terms).
  const double average = b.penalty_only ? 0.0 : (interior ? 0.5 : 1.0);
  const LineRule rule = gauss_legendre(b.quadrature_points);

  for (int q = 0; q < rule.count; ++q) {
    const double t = rule.t[q];
    Side plus, minus;
    evaluate_side(b, ed[0], ed[1], t, b.positions, plus);
    if (interior) evaluate_side(b, ed[2], ed[3], -t, b.positions, minus);
    const double ds = std::sqrt(dot3(plus.tangent, plus.tangent)) * rule.weight[q];
    double tau[3] = {plus.tangent[0], plus.tangent[1], plus.tangent[2]};
    normalize3(tau);

    // Rows over the edge's local basis: G = [[g]] (jump of the hinge rotation measure) and
    // Mbar = {m_nunu} (average normal bending moment), each 3 columns per basis function.
    double G[2 * max_element_nodes][3] = {}, M[2 * max_element_nodes][3] = {};
    for (int side = 0; side < (interior ? 2 : 1); ++side) {
      const Side& s = side == 0 ? plus : minus;
      const ShellSection& sec = side == 0 ? sp : sm;
      const double nu_p = sec.poisson_ratio;
      const double dm = side == 0 ? dm_plus : dm_minus;
      const double sign = side == 0 ? 1.0 : -1.0;
      double nu_vec[3], e1[3], e2[3];
      cross3(s.point.t0, tau, nu_vec);
      frame_along(s.point, tau, e1, e2);  // e1 = tau, e2 = t0 x tau = nu
      for (int a = 0; a < npe; ++a) {
        double T[9], Bb[9];
        normal_change_operator(s.point, s.shape.dN[a], T);
        bending_rows(s.point, e1, e2, s.shape.dN[a], s.shape.d2N[a], Bb);
        const int i = side * npe + a;
        for (int c = 0; c < 3; ++c) {
          G[i][c] = sign * (nu_vec[0] * T[0 * 3 + c] + nu_vec[1] * T[1 * 3 + c] + nu_vec[2] * T[2 * 3 + c]);
          // m_nunu = D (nu rho_11 + rho_22) in the frame (tau, nu).
          M[i][c] = average * dm * (nu_p * Bb[0 * 3 + c] + Bb[1 * 3 + c]);
        }
      }
    }
    const double* R = rotations ? rotations + (e * rule.count + q) * 9 : nullptr;
    double gd = 0, md = 0;  // G . d and M . d for the corrective force, d = X0 - R^T X0
    if (R && f) {
      for (int side = 0; side < (interior ? 2 : 1); ++side) {
        const int element = ed[2 * side];
        for (int a = 0; a < npe; ++a) {
          const double* x = b.positions + 3 * static_cast<long>(b.connectivity[static_cast<long>(element) * npe + a]);
          const int i = side * npe + a;
          for (int k = 0; k < 3; ++k) {
            const double d = x[k] - (R[0 * 3 + k] * x[0] + R[1 * 3 + k] * x[1] + R[2 * 3 + k] * x[2]);
            gd += G[i][k] * d;
            md += M[i][k] * d;
          }
        }
      }
    }
    if (R) {
      for (int i = 0; i < nb; ++i) {
        double g2[3], m2[3];
        for (int c = 0; c < 3; ++c) {
          g2[c] = G[i][0] * R[c * 3 + 0] + G[i][1] * R[c * 3 + 1] + G[i][2] * R[c * 3 + 2];
          m2[c] = M[i][0] * R[c * 3 + 0] + M[i][1] * R[c * 3 + 1] + M[i][2] * R[c * 3 + 2];
        }
        for (int c = 0; c < 3; ++c) G[i][c] = g2[c], M[i][c] = m2[c];
      }
    }
    // K += ds (penalty G^T G + M^T G + G^T M).
    for (int i = 0; i < nb; ++i)
      for (int j = 0; j < nb; ++j) {
        double* blk = K + (i * nb + j) * 9;
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c)
            blk[r * 3 + c] += ds * (penalty * G[i][r] * G[j][c] + M[i][r] * G[j][c] + G[i][r] * M[j][c]);
      }
    if (R && f)
      for (int i = 0; i < nb; ++i)
        for (int r = 0; r < 3; ++r) f[i * 3 + r] += ds * (penalty * G[i][r] * gd + M[i][r] * gd + G[i][r] * md);
  }
}

}  // namespace

void shell_element_stiffness_reference(const ElementBatch& batch, const double* rotations, double* blocks,
                                       double* forces) {
  for (std::int64_t e = 0; e < batch.count; ++e) element_stiffness_reference(batch, e, rotations, blocks, forces);
}

void shell_edge_stiffness_reference(const EdgeBatch& batch, const double* rotations, double* blocks, double* forces) {
  for (std::int64_t e = 0; e < batch.count; ++e) edge_stiffness_reference(batch, e, rotations, blocks, forces);
}

}  // namespace dgtex::kernels
